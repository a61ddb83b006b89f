//! Refusing an image too large for this machine before anything is loaded
//! or allocated.

use rtgi_math::Vec3;
use rtgi_render::PixelSum;

use crate::JobError;

/// Bytes a pixel of a render holds: its exact sums, a pass's sums beside
/// them, and two images of floats (the mean, and the half image or the
/// denoised one).
pub fn bytes_per_pixel() -> u64 {
    (2 * std::mem::size_of::<PixelSum>() + 2 * std::mem::size_of::<Vec3>()) as u64
}

/// Refuses `width` × `height` when the render would need more memory than
/// is available (when that is known).
pub fn check_memory(width: u32, height: u32) -> Result<(), JobError> {
    let needed = width as u64 * height as u64 * bytes_per_pixel();
    match available_memory() {
        Some(available) if needed > available => Err(JobError::Memory {
            width,
            height,
            needed_gib: needed as f64 / (1u64 << 30) as f64,
            available_gib: available as f64 / (1u64 << 30) as f64,
        }),
        _ => Ok(()),
    }
}

/// Memory available to new allocations (Linux's MemAvailable), if known.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pixel_costs_its_sums_twice_and_two_images() {
        assert_eq!(bytes_per_pixel(), 2 * std::mem::size_of::<PixelSum>() as u64 + 24);
        assert!(check_memory(64, 64).is_ok());
        if available_memory().is_some() {
            assert!(matches!(check_memory(1 << 20, 1 << 20), Err(JobError::Memory { .. })));
        }
    }
}
