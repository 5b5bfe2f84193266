//! Lights inside or partly inside a closed mesh (issue 69 item 1): a lamp in a closed housing,
//! a panel set into a closed slab. DCS counts such a mesh from both sides (a segment may enter
//! it and end on the light without leaving), in its silhouettes and in its integration
//! constant alike, and agrees with the reference sample for sample, for every light shape.

use std::sync::Arc;

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_dcs::Dcs;
use shadow_ref::Reference;

/// A closed, outward-facing box.
fn cuboid(lo: Vec3, hi: Vec3) -> MeshDesc {
    let p = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let v: Vec<Vec3> = (0..8)
        .map(|i| p(i & 4 != 0, i & 2 != 0, i & 1 != 0))
        .collect();
    let f = vec![
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ];
    MeshDesc::new(v, f)
}

/// A floor under a closed housing from y = 0.4 to 1.4.
fn housing() -> SceneRef {
    let mut b = SceneBuilder::new();
    b.push_mesh(MeshDesc::new(
        vec![
            Vec3::new(-3.0, 0.0, -3.0),
            Vec3::new(3.0, 0.0, -3.0),
            Vec3::new(3.0, 0.0, 3.0),
            Vec3::new(-3.0, 0.0, 3.0),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
    ))
    .unwrap();
    b.push_mesh(cuboid(Vec3::new(-0.5, 0.4, -0.5), Vec3::new(0.5, 1.4, 0.5)))
        .unwrap();
    Arc::new(b.build().unwrap())
}

fn lights_at(c: Vec3) -> Vec<(&'static str, Light)> {
    let one = Radiance::Constant(Vec3::ONE);
    let down = Vec3::NEG_Y;
    vec![
        (
            "rectangle",
            Arc::new(RectLight::facing(c, down, 0.4, 0.3, one.clone()).unwrap()),
        ),
        (
            "disk",
            Arc::new(DiskLight::new(c, down, 0.2, one.clone()).unwrap()),
        ),
        (
            "polygon",
            Arc::new(
                PolygonLight::new(
                    vec![
                        // Clockwise from above: it faces down, as the others.
                        c + Vec3::new(0.2, 0.0, -0.15),
                        c + Vec3::new(0.0, 0.0, 0.2),
                        c + Vec3::new(-0.2, 0.0, -0.15),
                    ],
                    one.clone(),
                )
                .unwrap(),
            ),
        ),
        ("sphere", Arc::new(SphereLight::new(c, 0.15, one).unwrap())),
    ]
}

/// DCS's and the same-samples reference's per-sample visibility and V.
fn agreement(scene: &SceneRef, light: &Light, view: &ViewSamples) -> (f64, f64, f64) {
    let dcs = Dcs::new(32, SamplingStrategy::Stratified, 5).unwrap();
    let reference = Reference::same_samples(dcs.light_sampler().unwrap().clone());
    let run = |t: &dyn ShadowTechnique| {
        t.prepare(scene.clone(), light.clone())
            .unwrap()
            .estimate(view, Outputs::PER_SAMPLE)
            .unwrap()
    };
    let (d, r) = (run(&dcs), run(&reference));
    let m = shadow_metrics::compare(&d.visibility, &r.visibility).unwrap();
    let mean = |e: &Estimate| {
        let v = &e.visibility;
        (0..v.len())
            .filter(|&i| v.is_valid(i))
            .map(|i| f64::from(v.value(i)))
            .sum::<f64>()
            / view.valid_count() as f64
    };
    (m.sample_agreement.unwrap(), mean(&d), mean(&r))
}

fn view(scene: &SceneRef) -> ViewSamples {
    let cam = Camera::look_at(
        Vec3::new(0.0, 3.0, 4.5),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        0.9,
    )
    .unwrap();
    ViewSamples::render(scene.as_ref(), &cam, 48, 36).unwrap()
}

#[test]
fn a_light_inside_a_closed_mesh_is_dark_outside_it_for_every_shape() {
    let scene = housing();
    let view = view(&scene);
    for (kind, light) in lights_at(Vec3::new(0.0, 0.9, 0.0)) {
        let (agree, dcs, reference) = agreement(&scene, &light, &view);
        assert_eq!(reference, 0.0, "{kind}: the housing hides the light");
        assert_eq!(dcs, 0.0, "{kind}: DCS sees the light through the housing");
        assert_eq!(agree, 1.0, "{kind}");
    }
}

#[test]
fn a_light_half_inside_a_closed_mesh_agrees_with_the_reference_for_every_shape() {
    let scene = housing();
    let view = view(&scene);
    // Across the housing's +x wall (x = 0.5): more inside, centred on the wall, more outside.
    for x in [0.45, 0.5, 0.56] {
        for (kind, light) in lights_at(Vec3::new(x, 0.9, 0.0)) {
            let (agree, dcs, reference) = agreement(&scene, &light, &view);
            assert!(
                reference > 0.0 && reference < 0.9,
                "{kind} at {x}: {reference}"
            );
            assert!(
                agree >= 0.999,
                "{kind} at {x}: agreement {agree}, V {dcs} against {reference}"
            );
            assert!(
                (dcs - reference).abs() < 0.005,
                "{kind} at {x}: V {dcs} against {reference}"
            );
        }
    }
}

#[test]
fn a_panel_flush_with_a_closed_slabs_face_agrees_with_the_reference() {
    let scene = housing();
    let view = view(&scene);
    // The light's plane is the housing's bottom face; half the panel lies on that face.
    for (kind, light) in lights_at(Vec3::new(0.45, 0.4, 0.1)) {
        if kind == "sphere" {
            continue;
        }
        let (agree, dcs, reference) = agreement(&scene, &light, &view);
        assert!(reference > 0.0, "{kind}: {reference}");
        assert!(
            agree >= 0.999,
            "{kind}: agreement {agree}, V {dcs} against {reference}"
        );
    }
}
