//! Cluster culling (`tile_pairs.wgsl`) is conservative: with it and without it AFSM gives the
//! same bit for every (view sample, light sample) pair, on scenes that exercise each of its
//! tests (a room around the light for the supporting-plane test, a mesh on a floor for the
//! depth and region tests, a sphere light whose far side lies beyond some view samples, a
//! disk light, semi-opaque casters, a furnished room lit through a wall, whose view samples
//! need one frustum per cube face, and grass, where most view samples are hidden from every
//! light sample after the first range of casters and their texels drop out of later ranges),
//! while testing fewer pairs. The penumbra-volume tests (`volume.rs`), of a batch's view
//! samples, super-tiles, tiles and texels, leave, under the interior's ceiling panel, fewer empty pairs than pairs that
//! hide something.

use std::sync::Arc;

use shadow_afsm::Afsm;
use shadow_afsm::statistics::AfsmCounter;
use shadow_core::gpu::context_for_test;
use shadow_core::prelude::*;
use shadow_metrics::compare;
use shadow_scenes::builtin;

#[test]
fn cluster_culling_changes_no_bit_and_tests_fewer_pairs() {
    if context_for_test("cluster_culling_changes_no_bit_and_tests_fewer_pairs").is_none() {
        return;
    }
    let mut fewer_somewhere = false;
    for name in [
        "cornell-box",
        "bunny",
        "sphere-light",
        "contact",
        "semi-opaque",
        "large-light-close",
        "grass",
        "interior-window",
        "interior",
    ] {
        let setup = builtin(name).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 64, 48).unwrap();
        let run = |culling: bool| {
            let mut a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 2 }, 3).unwrap();
            if !culling {
                a = a.without_cluster_culling();
            }
            a.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
                .unwrap()
                .estimate(&view, Outputs::VISIBILITY)
                .unwrap()
        };
        let (culled, plain) = (run(true), run(false));
        let m = compare(&culled.visibility, &plain.visibility).unwrap();
        let count = |e: &Estimate, k: AfsmCounter| e.stats.counter(k).expect("AFSM counts it");
        println!(
            "{name:<18} pairs tested {} -> {}, tiles culled {}, texels culled by depth {}, \
             texels hidden {}, texels culled by volume {}, empty pairs {}, agreement {:.7}",
            count(&plain, AfsmCounter::PairsTested),
            count(&culled, AfsmCounter::PairsTested),
            count(&culled, AfsmCounter::TilesCulled),
            count(&culled, AfsmCounter::TexelsCulledByDepth),
            count(&culled, AfsmCounter::TexelsHidden),
            count(&culled, AfsmCounter::TexelsCulledByVolume),
            count(&culled, AfsmCounter::PairsEmpty),
            m.sample_agreement.unwrap()
        );
        assert_eq!(m.sample_agreement, Some(1.0), "{name}: {m:?}");
        assert_eq!(m.max_abs, 0.0, "{name}");
        assert_eq!(count(&plain, AfsmCounter::TilesCulled), 0, "{name}");
        assert!(
            count(&culled, AfsmCounter::PairsTested) <= count(&plain, AfsmCounter::PairsTested),
            "{name}"
        );
        fewer_somewhere |=
            count(&culled, AfsmCounter::PairsTested) * 2 < count(&plain, AfsmCounter::PairsTested);
        if name.starts_with("interior") || name == "bunny" {
            assert!(
                count(&culled, AfsmCounter::TexelsCulledByVolume) > 0,
                "{name}"
            );
        }
        if name.starts_with("interior") {
            // Whole super-tiles of the rooms' walls lie outside most casters' volumes, and
            // each cube face's view samples outside most of the room's.
            assert!(count(&culled, AfsmCounter::SuperTilesCulled) > 0, "{name}");
            assert!(count(&culled, AfsmCounter::CastersCulled) > 0, "{name}");
        }
        assert_eq!(count(&plain, AfsmCounter::SuperTilesCulled), 0, "{name}");
        assert_eq!(count(&plain, AfsmCounter::CastersCulled), 0, "{name}");
        if name == "interior" {
            // Measured 0.28 at 128x96 (issue 48 asks for below one half).
            let empty = count(&culled, AfsmCounter::PairsEmpty) as f64;
            let share = empty / count(&culled, AfsmCounter::PairsTested) as f64;
            assert!(share < 0.5, "{name}: {share:.3} of the tested pairs empty");
        }
        if name == "grass" {
            assert!(count(&culled, AfsmCounter::TexelsHidden) > 0, "{name}");
            assert_eq!(count(&plain, AfsmCounter::TexelsHidden), 0, "{name}");
        }
    }
    assert!(
        fewer_somewhere,
        "culling should at least halve the pairs on one of these scenes"
    );
}
