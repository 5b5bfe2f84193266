//! Mutation fuzzing of the three loaders (issue 51): valid glTF, GLB and OBJ seeds, each case
//! one to four random edits (byte flips, structural characters, extreme numbers, cuts, repeats,
//! deletions), loaded, and what loads is rendered (view samples and the reference at four
//! samples). A case holds when nothing panics, it finishes in 30 s, and a loaded scene gives
//! finite visibility in [0, 1].
//!
//! `cargo test` runs a bounded number of cases per loader. For a long run, give the seconds per
//! loader: `SHADOW_FUZZ_SECONDS=600 cargo test --release -p shadow-conformance --test
//! fuzz_loaders -- --test-threads 1 --nocapture`. A failing input is written to
//! `target/fuzz-failures/` and named in the failure.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use shadow_core::prelude::*;
use shadow_io::load::{LoadLimits, load_gltf_slice, load_obj_slice};

/// Cases per loader in `cargo test` (a few seconds each in the test profile).
const BOUNDED_CASES: usize = 400;
/// A case that takes longer than this is a hang.
const CASE_LIMIT: Duration = Duration::from_secs(30);

/// xorshift64*: a fixed sequence per seed, so a failure is reproducible from its case number.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const TOKENS: [&str; 14] = [
    "1e38",
    "-1",
    "0",
    "4294967295",
    "18446744073709551615",
    "-9223372036854775808",
    "NaN",
    "nan",
    "1e-45",
    "3.4e39",
    "999999999",
    "\"../../etc/passwd\"",
    "null",
    "[]",
];
const CHARS: [u8; 14] = [
    b'{', b'}', b'[', b']', b',', b'"', b'-', b'9', b'e', b'/', b' ', b'\n', 0, 0xff,
];

/// The byte range of the number nearest after `at`, if any.
fn number_at(b: &[u8], at: usize) -> Option<std::ops::Range<usize>> {
    let is_num = |c: u8| c.is_ascii_digit() || c == b'.' || c == b'-' || c == b'e';
    let start = (at..b.len()).find(|&i| b[i].is_ascii_digit())?;
    let mut lo = start;
    while lo > 0 && is_num(b[lo - 1]) {
        lo -= 1;
    }
    let mut hi = start;
    while hi < b.len() && is_num(b[hi]) {
        hi += 1;
    }
    Some(lo..hi)
}

fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(3) {
        let at = rng.below(b.len() + 1);
        // Half the edits replace a number with an extreme one, which keeps the file's
        // structure (and so reaches the checks after parsing); the rest break anything.
        if rng.below(2) == 0
            && let Some(r) = number_at(&b, at)
        {
            let t = TOKENS[rng.below(11)].as_bytes();
            b.splice(r, t.iter().copied());
            continue;
        }
        match rng.below(6) {
            0 if !b.is_empty() => {
                let i = at.min(b.len() - 1);
                b[i] ^= 1 << rng.below(8);
            }
            1 if !b.is_empty() => {
                let i = at.min(b.len() - 1);
                b[i] = CHARS[rng.below(CHARS.len())];
            }
            2 => b.truncate(at),
            3 => {
                let len = rng.below(64).min(b.len() - at);
                let piece = b[at..at + len].to_vec();
                b.splice(at..at, piece);
            }
            4 => {
                let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                b.splice(at..at, t.iter().copied());
            }
            _ => {
                let len = rng.below(16).min(b.len() - at);
                b.drain(at..at + len);
            }
        }
    }
    b
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// A floor, an occluder and an emissive square as glTF JSON with its buffer embedded, or the
/// JSON and the buffer apart (for GLB).
fn gltf_seed(embedded: bool) -> (String, Vec<u8>) {
    let quad = |y: f32, h: f32| -> Vec<f32> {
        [(-h, -h), (h, -h), (h, h), (-h, h)]
            .iter()
            .flat_map(|&(x, z)| [x, y, z])
            .collect()
    };
    let mut bin: Vec<u8> = Vec::new();
    for (y, h) in [(0.0, 3.0), (1.0, 0.4), (2.5, 0.5)] {
        for v in quad(y, h) {
            bin.extend(v.to_le_bytes());
        }
    }
    for i in [0u16, 2, 1, 0, 3, 2] {
        bin.extend(i.to_le_bytes());
    }
    let uri = if embedded {
        format!(
            r#","uri":"data:application/octet-stream;base64,{}""#,
            base64(&bin)
        )
    } else {
        String::new()
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1,2,3]}}],
"nodes":[{{"mesh":0}},{{"mesh":1}},{{"mesh":2,"rotation":[1,0,0,0],"translation":[0,5,0]}},{{"camera":0,"translation":[0,2,6]}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.01}}}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.5,0.5,1]}}}},{{"emissiveFactor":[1,1,1]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":3,"material":0}}]}},
{{"primitives":[{{"attributes":{{"POSITION":1}},"indices":3,"material":0}}]}},
{{"primitives":[{{"attributes":{{"POSITION":2}},"indices":3,"material":1}}]}}],
"buffers":[{{"byteLength":{len}{uri}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":144}},{{"buffer":0,"byteOffset":144,"byteLength":12}}],
"accessors":[
{{"bufferView":0,"byteOffset":0,"componentType":5126,"count":4,"type":"VEC3","min":[-3,0,-3],"max":[3,0,3]}},
{{"bufferView":0,"byteOffset":48,"componentType":5126,"count":4,"type":"VEC3","min":[-0.4,1,-0.4],"max":[0.4,1,0.4]}},
{{"bufferView":0,"byteOffset":96,"componentType":5126,"count":4,"type":"VEC3","min":[-0.5,2.5,-0.5],"max":[0.5,2.5,0.5]}},
{{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
        len = bin.len()
    );
    (json, bin)
}

const OBJ_SEED: &str = "# a floor, a box and a pentagon\n\
o floor\nv -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nvt 0 0\nvn 0 1 0\nf 1/1/1 4/1/1 3/1/1 2/1/1\n\
o box\nv -0.3 0.5 -0.3\nv 0.3 0.5 -0.3\nv 0.3 1 -0.3\nv -0.3 1 -0.3\n\
v -0.3 0.5 0.3\nv 0.3 0.5 0.3\nv 0.3 1 0.3\nv -0.3 1 0.3\n\
f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 7 8 12 11\nf 5 9 12 8\nf 6 7 11 10\n\
g penta\nv 1 1.5 0\nv 1.3 1.5 0.2\nv 1.2 1.5 0.5\nv 0.8 1.5 0.5\nv 0.7 1.5 0.2\nf -5 -4 -3 -2 -1\n";

/// Loads, then renders what loaded; `Ok(true)` when the case loaded and rendered, `Err`
/// describes a broken property.
fn check(kind: &str, bytes: &[u8]) -> Result<bool, String> {
    let limits = LoadLimits::default();
    let loaded = match kind {
        "obj" => load_obj_slice(bytes, "fuzz", &limits),
        _ => load_gltf_slice(bytes, None, "fuzz", &limits),
    };
    let Ok(mut setup) = loaded else {
        return Ok(false);
    };
    if setup.scene.triangle_count() > 100_000 {
        return Ok(false);
    }
    if setup.lights.is_empty() {
        setup.lights.push(std::sync::Arc::new(
            RectLight::facing(
                glam::Vec3::new(0.0, 4.0, 0.0),
                glam::Vec3::NEG_Y,
                1.0,
                1.0,
                Radiance::Constant(glam::Vec3::ONE),
            )
            .map_err(|e| e.to_string())?,
        ));
    }
    let Ok(view) = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 16, 12)
    else {
        return Ok(false);
    };
    let reference = shadow_ref::Reference::stratified(4, 1).map_err(|e| e.to_string())?;
    let Ok(prepared) = reference.prepare(setup.scene.clone(), setup.lights[0].clone()) else {
        return Ok(false);
    };
    let Ok(est) = prepared.estimate(&view, Outputs::VISIBILITY) else {
        return Ok(false);
    };
    for i in 0..est.visibility.len() {
        let v = est.visibility.value(i);
        if !(0.0..=1.0).contains(&v) {
            return Err(format!("pixel {i} has visibility {v}"));
        }
    }
    Ok(true)
}

fn fuzz(kind: &str, seed: &[u8], rng_seed: u64) {
    let seconds: Option<u64> = std::env::var("SHADOW_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok());
    let start = Instant::now();
    let mut rng = Rng(rng_seed);
    let (mut case, mut rendered) = (0usize, 0usize);
    // The seed itself loads and renders.
    assert_eq!(check(kind, seed), Ok(true), "{kind} seed");
    loop {
        match seconds {
            Some(s) if start.elapsed() >= Duration::from_secs(s) => break,
            None if case >= BOUNDED_CASES => break,
            _ => {}
        }
        let input = mutate(seed, &mut rng);
        let t0 = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| check(kind, &input)));
        let took = t0.elapsed();
        let failure = match outcome {
            Err(_) => Some("panicked".to_string()),
            Ok(Err(e)) => Some(e),
            Ok(Ok(_)) if took > CASE_LIMIT => Some(format!("took {took:?}")),
            Ok(Ok(r)) => {
                rendered += usize::from(r);
                None
            }
        };
        if let Some(why) = failure {
            let dir =
                std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fuzz-failures");
            std::fs::create_dir_all(&dir).ok();
            let file = dir.join(format!("{kind}-{rng_seed}-{case}"));
            std::fs::write(&file, &input).ok();
            panic!("{kind} case {case}: {why}; input in {}", file.display());
        }
        case += 1;
    }
    println!(
        "{kind}: {case} cases ({rendered} loaded and rendered) in {:.1} s without a panic, hang \
         or invalid value",
        start.elapsed().as_secs_f64()
    );
    // The mutations must leave a share of loadable files (2%; most edits land in the buffer
    // data and are refused), or the deep path goes untested.
    assert!(
        rendered * 50 >= case,
        "{kind}: only {rendered} of {case} cases loaded"
    );
}

#[test]
fn gltf_json_survives_mutation() {
    let (json, _) = gltf_seed(true);
    fuzz("gltf", json.as_bytes(), 0x9e37_79b9_7f4a_7c15);
}

#[test]
fn glb_survives_mutation() {
    let (json, bin) = gltf_seed(false);
    fuzz(
        "glb",
        &shadow_io::load::glb_bytes(&json, &bin),
        0xd1b5_4a32_d192_ed03,
    );
}

#[test]
fn obj_survives_mutation() {
    fuzz("obj", OBJ_SEED.as_bytes(), 0x2545_f491_4f6c_dd1d);
}
