//! A bounded fuzz run in the normal test suite: every file of the fixed
//! corpus `tests/corpus/<format>/` (seeds and deterministic mutations of
//! them, plus inputs the fuzzers found) loads to `Ok` or a clean `Err`,
//! never a panic.
//!
//! `cargo test -p rtgi-tests --test scene loader_corpus -- --ignored` rewrites the
//! seeds and mutations (`seed-*`, `mut-*`); other files (`crash-*`) are kept.

use std::panic::{AssertUnwindSafe, catch_unwind};

use rtgi_tests::corpus::{FORMATS, corpus_dir, load_input};

#[test]
fn every_corpus_file_loads_or_fails_cleanly() {
    let mut panicked = Vec::new();
    let mut counts = Vec::new();
    for format in FORMATS {
        let dir = corpus_dir().join(format);
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.unwrap().path())
            .collect();
        paths.sort();
        counts.push((format, paths.len()));
        for path in paths {
            let bytes = std::fs::read(&path).unwrap();
            match catch_unwind(AssertUnwindSafe(|| load_input(format, &bytes))) {
                Err(_) => panicked.push(path.display().to_string()),
                // The seeds are valid files: they must load.
                Ok(Err(e)) if path.file_name().unwrap().to_string_lossy().starts_with("seed-") => {
                    panic!("{}: {e}", path.display())
                }
                Ok(_) => {}
            }
        }
    }
    assert!(panicked.is_empty(), "loading these panicked:\n{}", panicked.join("\n"));
    assert!(counts.iter().all(|&(_, n)| n >= 10), "corpus too small: {counts:?}");
}

const OBJ_SEEDS: &[&str] = &[
    "# a textured triangle\nmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1\n",
    "o quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\ng front\nf -4//-1 -3//-1 -2//-1 -1//-1\nusemtl b\nf 1 3 4\n",
    "mtllib m.mtl other.mtl\nv 0 0 0 1\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nv 0.5 -0.5 0\ns 1\nusemtl missing\nf 1 2 3 4 5 6\nl 1 2\np 3\n",
    "v 1e-30 0 0\nv 0 1e30 0\nv 0 0 -0\nvt 0.5 0.5 0\nf 1/1 2/1 3/1\nf 3/1 2/1 1/1\n",
];

const MTL_SEEDS: &[&str] = &[
    "# every statement\nnewmtl a\nKa 0.1 0.1 0.1\nKd 0.8 0.2 0.2\nKs 0.5\nKe 0 0 0\nTf 1 1 1\nNs 96\nNi 1.45\nd 1\nillum 2\nmap_Kd tex.png\n",
    "newmtl b\nKd 0.5\nTr 0.25\nillum 7\nmap_Kd -bm 0.5 -s 1 1 1 -o 0 0 0 -clamp on tex.png\nbump -bm 2 normal.png\nnewmtl c\nPr 0.5\nPm 1\nPs 0.1\nPc 0.2\nPcr 0.03\naniso 0\nanisor 0\nmap_Pr rough.png\n",
    "newmtl c\nd -halo 0.5\nillum 3\nsharpness 60\nmap_Kd -blendu on -blendv off -mm 0 1 -texres 512 -imfchan r -cc off my texture.png\nnewmtl a\nKd spectral f.rfl\nKs xyz 1 1 1\n",
];

/// glTF seeds: a triangle with indices, normals, texture coordinates, a
/// textured material, a camera, a light and a small hierarchy.
fn gltf_seeds() -> Vec<String> {
    let full = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,3]}],
"nodes":[{"children":[1,2],"translation":[0,0,1]},{"mesh":0,"rotation":[0,0,0,1],"scale":[1,2,1]},
{"camera":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,5,1]},{"mesh":0,"extensions":{"KHR_lights_punctual":{"light":0}}}],
"extensionsUsed":["KHR_lights_punctual","KHR_materials_transmission"],
"extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","spot":{"innerConeAngle":0.1,"outerConeAngle":0.5},"intensity":5}]}},
"cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1,"aspectRatio":1.5}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2},"indices":3,"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0},"metallicFactor":0.5},"normalTexture":{"index":0},
"alphaMode":"MASK","extensions":{"KHR_materials_transmission":{"transmissionFactor":0.5}}}],
"textures":[{"source":0,"sampler":0}],"samplers":[{"wrapS":33071,"wrapT":33648}],"images":[{"uri":"tex.png"}],
"buffers":[{"uri":"tri.bin","byteLength":104}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":72,"byteStride":12},{"buffer":0,"byteOffset":72,"byteLength":24},{"buffer":0,"byteOffset":96,"byteLength":6}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]},
{"bufferView":0,"byteOffset":36,"componentType":5126,"count":3,"type":"VEC3"},
{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},
{"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;
    // The same triangle with its buffer embedded as a data URI, and an image in a buffer view.
    let bin = rtgi_tests::corpus::referenced_bin();
    let data_uri = format!("data:application/octet-stream;base64,{}", base64_encode(&bin));
    let embedded = format!(
        r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":4}},{{"attributes":{{"POSITION":0}},"mode":1}}]}}],
"images":[{{"bufferView":0,"mimeType":"image/png"}}],"textures":[{{"source":0}}],"materials":[{{"emissiveTexture":{{"index":0}}}}],
"buffers":[{{"uri":"{data_uri}","byteLength":104}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}}]}}"#
    );
    vec![full.to_owned(), embedded]
}

fn base64_encode(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
        for i in 0..4 {
            out.push(if i <= chunk.len() { ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// A GLB container: the JSON chunk (padded with spaces) and a binary chunk.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

fn glb_seeds() -> Vec<Vec<u8>> {
    let json = gltf_seeds()[0].replace(r#"{"uri":"tri.bin","byteLength":104}"#, r#"{"byteLength":104}"#);
    vec![glb(&json, &rtgi_tests::corpus::referenced_bin())]
}

const TOML_SEEDS: &[&str] = &[
    "[[mesh]]\nfile = \"a.obj\"\n[[mesh]]\nfile = \"b.obj\"\n[camera]\nposition = [0, 1, 5]\nlook_at = [0, 0, 0]\nvertical_fov_degrees = 40\naspect = 1.5\n",
    "[[mesh]]\nfile = \"sub/a.obj\"\n[camera]\nposition = [0, 0, 0]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nvertical_fov_degrees = 60\n",
];

/// Words that make parsers take unusual paths.
const TOKENS: &[&str] = &[
    "-1",
    "0",
    "-0",
    "1e39",
    "-1e39",
    "nan",
    "inf",
    "4294967295",
    "65536",
    "2147483648",
    "99999999999",
    "0.5",
    " ",
    "\n",
    "\t",
    "/",
    "//",
    "\\",
    "-",
    "\"",
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "null",
    "true",
    "f 1 2",
    "v 1",
    "vt",
    "vn",
    "usemtl ",
    "mtllib ",
    "newmtl ",
    "Kd",
    "map_Kd -s",
    "-o",
    "illum 99",
    "../",
    "/etc/passwd",
    "\"children\":[0]",
    "\"mesh\":0",
    "\"indices\":0",
    "\"bufferView\":9",
    "\"byteStride\":4",
    "\"count\":1000000",
    "\"type\":\"MAT4\"",
    "\"componentType\":5121",
    "\"uri\":\"../x.bin\"",
    "\u{feff}",
    "\u{0}",
    "é",
];

/// xorshift64*: deterministic, so the corpus is the same on every machine.
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

/// One to four random edits: byte changes, deletions, duplications,
/// inserted tokens, numbers replaced, lines swapped.
fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut data = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(data.len() + 1);
        match rng.below(6) {
            0 if !data.is_empty() => {
                let i = rng.below(data.len());
                data[i] = rng.next() as u8;
            }
            1 => {
                let end = (at + 1 + rng.below(16)).min(data.len());
                data.drain(at.min(end)..end);
            }
            2 => {
                let end = (at + 1 + rng.below(64)).min(data.len());
                let copy = data[at.min(end)..end].to_vec();
                data.splice(at..at, copy);
            }
            3 | 4 => {
                // Replace the number at `at` (or insert a token if there is none).
                let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let is_digit = |b: &u8| b.is_ascii_digit() || *b == b'.';
                let start = data[..at].iter().rposition(|b| !is_digit(b)).map_or(0, |p| p + 1);
                let end = data[at..].iter().position(|b| !is_digit(b)).map_or(data.len(), |p| at + p);
                data.splice(start..end, token.iter().copied());
            }
            _ => {
                let lines: Vec<&[u8]> = data.split(|&b| b == b'\n').collect();
                if lines.len() > 2 {
                    let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                    let mut lines: Vec<Vec<u8>> = lines.iter().map(|l| l.to_vec()).collect();
                    lines.swap(a, b);
                    data = lines.join(&b'\n');
                }
            }
        }
    }
    data
}

#[test]
#[ignore = "rewrites tests/corpus; run by hand after changing the seeds or the mutator"]
fn regenerate_corpus() {
    let seeds: Vec<(&str, Vec<Vec<u8>>, usize)> = vec![
        ("obj", OBJ_SEEDS.iter().map(|s| s.as_bytes().to_vec()).collect(), 90),
        ("mtl", MTL_SEEDS.iter().map(|s| s.as_bytes().to_vec()).collect(), 90),
        ("gltf", gltf_seeds().into_iter().map(String::into_bytes).collect(), 90),
        ("glb", glb_seeds(), 30),
        ("toml", TOML_SEEDS.iter().map(|s| s.as_bytes().to_vec()).collect(), 20),
    ];
    let mut rng = Rng(0x5eed_2026_0015);
    for (format, seeds, mutations) in seeds {
        let dir = corpus_dir().join(format);
        std::fs::create_dir_all(&dir).unwrap();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("seed-") || name.starts_with("mut-") {
                std::fs::remove_file(path).unwrap();
            }
        }
        for (i, seed) in seeds.iter().enumerate() {
            std::fs::write(dir.join(format!("seed-{i}.{format}")), seed).unwrap();
        }
        for i in 0..mutations {
            let seed = &seeds[i % seeds.len()];
            std::fs::write(dir.join(format!("mut-{i:03}.{format}")), mutate(seed, &mut rng)).unwrap();
        }
    }
}
