//! Writes the voxel world of `tests/tests/render/cutouts.rs` (OBJ, MTL and a PNG atlas)
//! into a folder: `voxel-world DIR [SIDE]`, SIDE columns a side (48 by
//! default, as in the test).

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let (Some(dir), side, None) = (args.next(), args.next(), args.next()) else {
        eprintln!("usage: voxel-world DIR [SIDE]");
        return ExitCode::from(2);
    };
    let side = match side.as_deref().map(str::parse::<i32>) {
        None => 48,
        Some(Ok(side)) if (1..=1024).contains(&side) => side,
        Some(_) => {
            eprintln!("voxel-world: SIDE must be a whole number from 1 to 1024, not {}", side.unwrap_or_default());
            return ExitCode::from(2);
        }
    };
    let dir = PathBuf::from(dir);
    match std::fs::create_dir_all(&dir).and_then(|()| rtgi_tests::voxel_world::voxel_world(&dir, side)) {
        Ok(obj) => {
            println!("{}", obj.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("voxel-world: cannot write into {}: {e}", dir.display());
            ExitCode::FAILURE
        }
    }
}
