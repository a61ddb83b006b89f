//! Writes an HDR gradient spanning eight stops as a linear OpenEXR file and
//! as PNGs through two tone maps, reads the EXR back and compares.
//!
//! `cargo run -p rtgi-image --example tone_map`

use rtgi_image::{HdrImage, ToneMap, ToneOperator, compare};
use rtgi_math::Vec3;

fn main() {
    let (width, height) = (64, 16);
    let mut image = HdrImage::new(width, height);
    for y in 0..height {
        for x in 0..width {
            // From 1/16 to 16: more than an 8-bit image can hold without a tone map.
            let radiance = 2f32.powf(x as f32 / (width - 1) as f32 * 8.0 - 4.0);
            image.set(x, y, Vec3::new(radiance, radiance * 0.8, radiance * 0.6));
        }
    }
    let folder = std::env::temp_dir().join(format!("rtgi-tone-map-{}", std::process::id()));
    std::fs::create_dir_all(&folder).expect("the temporary folder is writable");
    let exr = folder.join("gradient.exr");
    image.write(&exr, &ToneMap::default()).expect("write the EXR");
    for operator in [ToneOperator::Clamp, ToneOperator::Aces] {
        let png = folder.join(format!("gradient-{}.png", operator.name()));
        image.write(&png, &ToneMap { exposure: -1.0, operator }).expect("write the PNG");
        println!("wrote {}", png.display());
    }
    // EXR stores the radiance itself (as half or full floats): it comes back almost unchanged.
    let back = HdrImage::read_exr(&exr).expect("read the EXR back");
    let difference = compare(&back, &image).expect("same size");
    println!("wrote and read {}: relative MSE {:.2e}", exr.display(), difference.relative_mse);
    assert!(difference.relative_mse < 1e-5);
    std::fs::remove_dir_all(&folder).ok();
}

#[test]
fn runs() {
    main();
}
