//! A function of two variables tabulated on a regular grid and read back
//! by bilinear interpolation: what the layered model's directional albedos
//! and the sheen's masking are stored as.
//!
//! The grid is over the unit square; each table maps its own variables
//! onto it (a cosine through its square root, a roughness through its
//! logarithm, …) so that the tabulated function is close to linear
//! between nodes where it varies fastest.

use std::ops::{Add, Mul};

/// Values at the nodes of an `nx` × `ny` grid over [0, 1]², node `(i, j)` at
/// `(i / (nx − 1), j / (ny − 1))`.
#[derive(Clone, Debug)]
pub(super) struct Table2<T> {
    nx: usize,
    ny: usize,
    /// Row-major by `j`: node `(i, j)` is at `j · nx + i`.
    values: Vec<T>,
}

impl<T: Copy + Add<Output = T> + Mul<f32, Output = T>> Table2<T> {
    /// Tabulates `f(x, y)` at every node.
    pub(super) fn build(nx: usize, ny: usize, mut f: impl FnMut(f32, f32) -> T) -> Self {
        assert!(nx >= 2 && ny >= 2, "a table needs two nodes along each axis to interpolate");
        let mut values = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            let y = j as f32 / (ny - 1) as f32;
            for i in 0..nx {
                values.push(f(i as f32 / (nx - 1) as f32, y));
            }
        }
        Self { nx, ny, values }
    }

    /// The bilinear interpolation at `(x, y)`, clamped to the unit square
    /// (a NaN coordinate reads the node at 0).
    pub(super) fn lookup(&self, x: f32, y: f32) -> T {
        let (i, tx) = cell(x, self.nx);
        let (j, ty) = cell(y, self.ny);
        let at = |i: usize, j: usize| self.values[j * self.nx + i];
        let lower = at(i, j) * (1.0 - tx) + at(i + 1, j) * tx;
        let upper = at(i, j + 1) * (1.0 - tx) + at(i + 1, j + 1) * tx;
        lower * (1.0 - ty) + upper * ty
    }
}

/// The cell of `n` nodes that `t` ∈ [0, 1] falls in, and where in it.
fn cell(t: f32, n: usize) -> (usize, f32) {
    let last = (n - 1) as f32;
    // `max` before `min` maps NaN to 0.
    let position = (t * last).max(0.0).min(last);
    let index = (position as usize).min(n - 2);
    (index, position - index as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_bilinear_functions_and_clamps() {
        let f = |x: f32, y: f32| 1.0 + 2.0 * x - 3.0 * y + 0.5 * x * y;
        let table = Table2::build(5, 7, f);
        for (x, y) in [(0.0, 0.0), (1.0, 1.0), (0.13, 0.77), (0.5, 0.999), (0.9, 0.01)] {
            assert!((table.lookup(x, y) - f(x, y)).abs() < 1e-5, "{x}, {y}");
        }
        assert_eq!(table.lookup(-3.0, 2.0), f(0.0, 1.0));
        assert_eq!(table.lookup(f32::NAN, 0.0), f(0.0, 0.0));
    }
}
