//! A light and a camera given on the command line, in place of the file's:
//!
//! * `--light rect:CENTER:NORMAL:WIDTHxHEIGHT`, `disk:CENTER:NORMAL:RADIUS` or
//!   `sphere:CENTER:RADIUS`, with `--light-radiance R,G,B` (or one value for all three;
//!   default 1);
//! * `--camera EYE:TARGET:FOV`, the vertical field of view in degrees, +Y up.
//!
//! Points and directions are `x,y,z` in the scene's units. The rectangle's sides follow
//! [`RectLight::facing`]: the same light a program builds with that call.

use std::sync::Arc;

use glam::Vec3;
use shadow_core::prelude::*;

/// `x,y,z`.
fn vec3(text: &str, what: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = text
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{what} `{text}`: {e} (expected x,y,z)"))?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(format!(
            "{what} `{text}`: expected three finite numbers x,y,z"
        )),
    }
}

/// A positive finite number.
fn positive(text: &str, what: &str) -> Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("{what} `{text}`: expected a positive number"))
}

/// `R,G,B` or one value for all three, non-negative.
pub fn radiance(text: Option<&str>) -> Result<Radiance, String> {
    let rgb = match text {
        None => Vec3::ONE,
        Some(t) if !t.contains(',') => Vec3::splat(
            t.trim()
                .parse::<f32>()
                .map_err(|e| format!("--light-radiance `{t}`: {e}"))?,
        ),
        Some(t) => vec3(t, "--light-radiance")?,
    };
    Radiance::constant(rgb).map_err(|e| format!("--light-radiance: {e}"))
}

/// The light a `--light` specification describes.
pub fn light(spec: &str, radiance: Radiance) -> Result<Light, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    let err = |e: shadow_core::light::LightError| format!("--light `{spec}`: {e}");
    let light: Light = match parts[..] {
        ["rect", center, normal, size] => {
            let (w, h) = size
                .split_once('x')
                .ok_or_else(|| format!("--light `{spec}`: size `{size}` is not WIDTHxHEIGHT"))?;
            Arc::new(
                RectLight::facing(
                    vec3(center, "light centre")?,
                    vec3(normal, "light normal")?,
                    positive(w, "light width")?,
                    positive(h, "light height")?,
                    radiance,
                )
                .map_err(err)?,
            )
        }
        ["disk", center, normal, radius] => Arc::new(
            DiskLight::new(
                vec3(center, "light centre")?,
                vec3(normal, "light normal")?,
                positive(radius, "light radius")?,
                radiance,
            )
            .map_err(err)?,
        ),
        ["sphere", center, radius] => Arc::new(
            SphereLight::new(
                vec3(center, "light centre")?,
                positive(radius, "light radius")?,
                radiance,
            )
            .map_err(err)?,
        ),
        _ => {
            return Err(format!(
                "--light `{spec}`: expected rect:CENTER:NORMAL:WIDTHxHEIGHT, \
                 disk:CENTER:NORMAL:RADIUS or sphere:CENTER:RADIUS"
            ));
        }
    };
    Ok(light)
}

/// The camera a `--camera EYE:TARGET:FOV` specification describes (FOV vertical, degrees).
pub fn camera(spec: &str) -> Result<Camera, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    let [eye, target, fov] = parts[..] else {
        return Err(format!(
            "--camera `{spec}`: expected EYE:TARGET:FOV (x,y,z:x,y,z:degrees)"
        ));
    };
    let fov = positive(fov, "camera field of view")?;
    if fov >= 180.0 {
        return Err(format!(
            "--camera `{spec}`: a field of view below 180 degrees"
        ));
    }
    Camera::look_at(
        vec3(eye, "camera eye")?,
        vec3(target, "camera target")?,
        Vec3::Y,
        fov.to_radians(),
    )
    .map_err(|e| format!("--camera `{spec}`: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specifications_build_the_lights_and_camera_they_name() {
        let one = radiance(None).unwrap();
        let r = light("rect:0,3,0:0,-1,0:1x0.5", one.clone()).unwrap();
        assert_eq!(r.kind(), LightKind::Rectangle);
        assert!((r.area() - 0.5).abs() < 1e-6);
        let d = light("disk:1,2,3:0,0,1:0.25", one.clone()).unwrap();
        assert_eq!(d.kind(), LightKind::Disk);
        assert!((d.center() - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        let s = light("sphere:0,4,0:0.5", radiance(Some("2,1,0.5")).unwrap()).unwrap();
        assert_eq!(s.kind(), LightKind::Sphere);
        assert!((s.radiance().mean() - Vec3::new(2.0, 1.0, 0.5)).length() < 1e-6);
        let c = camera("0,2,6:0,0,0:45").unwrap();
        assert!((c.position() - Vec3::new(0.0, 2.0, 6.0)).length() < 1e-6);
        assert!((c.yfov() - 45f32.to_radians()).abs() < 1e-6);
        for bad in [
            "rect:0,3,0:0,-1,0:1",
            "rect:0,3:0,-1,0:1x1",
            "disk:0,0,0:0,0,0:1",
            "sphere:0,0,0:-1",
            "cone:0,0,0:1",
        ] {
            assert!(light(bad, one.clone()).is_err(), "{bad}");
        }
        for bad in ["0,2,6:0,0,0", "0,2,6:0,2,6:45", "0,2,6:0,0,0:200"] {
            assert!(camera(bad).is_err(), "{bad}");
        }
        assert!(radiance(Some("-1")).is_err());
    }
}
