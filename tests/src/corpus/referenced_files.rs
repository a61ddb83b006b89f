//! The files a fuzzed or corpus scene may reference, by extension: shared
//! by the test corpus (`rtgi_tests::corpus`) and the fuzz targets
//! (`fuzz/src/lib.rs` includes this file), so that an input the fuzzers
//! find behaves the same in `tests/corpus/`. Plain std, no dependencies.

use std::path::Path;

/// An OBJ file that uses the materials of `m.mtl`, through which MTL
/// inputs are loaded.
pub const MTL_HOST_OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 3/3 2/2\nusemtl c\nf 3 2 1\n";

/// The MTL that OBJ inputs reference as any `*.mtl`.
pub const REFERENCED_MTL: &str = "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd tex.png\nnewmtl b\nKe 1 1 1\n";

/// The OBJ that descriptions reference as any `*.obj`.
pub const REFERENCED_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A 2 × 2 RGBA PNG, for any referenced image.
pub const REFERENCED_PNG: [u8; 74] = [
    137, 80, 78, 71, 13, 10, 26, 10, 0, 0, 0, 13, 73, 72, 68, 82, 0, 0, 0, 2, 0, 0, 0, 2, 8, 6, 0, 0, 0, 114, 182, 13,
    36, 0, 0, 0, 17, 73, 68, 65, 84, 120, 156, 99, 56, 145, 98, 244, 31, 132, 25, 96, 12, 0, 84, 64, 9, 117, 166, 104,
    144, 194, 0, 0, 0, 0, 73, 69, 78, 68, 174, 66, 96, 130,
];

/// The binary buffer any `*.bin` reference gets: three positions (36
/// bytes), three normals (36), three texture coordinates (24) and the
/// indices 0, 1, 2 as u16 (6, padded to 8): 104 bytes.
pub fn referenced_bin() -> Vec<u8> {
    let floats: [f32; 24] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0,
        0.0, 1.0,
    ];
    let mut bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bytes.extend([0, 0, 1, 0, 2, 0, 0, 0]);
    bytes
}

/// The bytes of a file a corpus scene references, chosen by its extension;
/// `mtl` is what `*.mtl` gives (the input itself, for MTL inputs).
pub fn referenced(name: &str, mtl: &[u8]) -> Option<Vec<u8>> {
    let extension = Path::new(name).extension()?.to_str()?.to_ascii_lowercase();
    match extension.as_str() {
        "mtl" => Some(mtl.to_vec()),
        "obj" => Some(REFERENCED_OBJ.as_bytes().to_vec()),
        "bin" => Some(referenced_bin()),
        "png" => Some(REFERENCED_PNG.to_vec()),
        _ => None,
    }
}
