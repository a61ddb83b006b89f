//! Run-time choice of the instruction set: the one module of the crate
//! that may use `unsafe`.
//!
//! The build targets x86-64-v2 (SSE4.2), so that the binary runs on any
//! such CPU. The hot loops ([`Kernel`]s) are compiled three times: for that
//! baseline, with AVX2 and FMA, and with AVX-512; [`dispatch`] runs the
//! widest the CPU supports. Calling a `#[target_feature]` function is
//! `unsafe` because running instructions the CPU lacks is undefined
//! behaviour; each call below is made only after the CPU was seen to have
//! every feature the function enables.
//!
//! The kernels are written as plain loops over fixed-size lanes that the
//! compiler vectorises for whichever instruction set the function is
//! compiled with; results are the same bits on every level (no fused
//! multiply-add is ever formed: Rust does not contract `a * b + c`), which
//! the tests of the wide BVHs check by running every level.
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicU8, Ordering};

use super::boxes::{FAR_OF_NEAR, PlaneRay, WideBoxes};
use super::packet::{IntervalRay, Lanes, PACKET, PacketRays};
use super::packet_triangles::{PacketHits, WatertightPacket};
use crate::wide::QuantisedNode;

/// The instruction sets the kernels are compiled for, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SimdLevel {
    /// SSE up to 4.2: the x86-64-v2 baseline, and every other architecture's default.
    Portable,
    /// AVX2 with FMA, BMI and LZCNT (x86-64-v3).
    Avx2,
    /// AVX-512 F, VL, BW, DQ and CD on top of AVX2 (x86-64-v4).
    Avx512,
}

impl SimdLevel {
    /// Every level, from the least to the most capable.
    pub const ALL: &'static [SimdLevel] = &[SimdLevel::Portable, SimdLevel::Avx2, SimdLevel::Avx512];

    /// The level's name in reports and for limiting it (`portable`, `avx2`, `avx512`).
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Portable => "portable",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
        }
    }

    /// The widest level this CPU supports.
    pub fn detected() -> SimdLevel {
        #[cfg(target_arch = "x86_64")]
        {
            let avx2 = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
                && std::arch::is_x86_feature_detected!("bmi1")
                && std::arch::is_x86_feature_detected!("bmi2")
                && std::arch::is_x86_feature_detected!("lzcnt");
            let avx512 = avx2
                && std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512bw")
                && std::arch::is_x86_feature_detected!("avx512dq")
                && std::arch::is_x86_feature_detected!("avx512cd");
            if avx512 {
                return SimdLevel::Avx512;
            }
            if avx2 {
                return SimdLevel::Avx2;
            }
        }
        SimdLevel::Portable
    }
}

impl rtgi_math::NamedChoice for SimdLevel {
    const KIND: &'static str = "SIMD level";
    const ALL: &'static [Self] = SimdLevel::ALL;
    fn name(self) -> &'static str {
        SimdLevel::name(self)
    }
}

impl std::fmt::Display for SimdLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The level in use, as `SimdLevel as u8`; `UNSET` until first asked.
static ACTIVE: AtomicU8 = AtomicU8::new(UNSET);
const UNSET: u8 = u8::MAX;

fn from_u8(value: u8) -> SimdLevel {
    SimdLevel::ALL[value as usize]
}

/// The level the kernels run at: the detected one, or lower if
/// [`limit_simd_level`] asked for it.
pub fn active_simd_level() -> SimdLevel {
    match ACTIVE.load(Ordering::Relaxed) {
        UNSET => {
            let detected = SimdLevel::detected();
            ACTIVE.store(detected as u8, Ordering::Relaxed);
            detected
        }
        value => from_u8(value),
    }
}

/// Runs the kernels at most at `level` from now on, in every thread (to
/// compare levels, or to rule one out); a level above what the CPU
/// supports is lowered to that. Returns the level now in use.
pub fn limit_simd_level(level: SimdLevel) -> SimdLevel {
    let level = level.min(SimdLevel::detected());
    ACTIVE.store(level as u8, Ordering::Relaxed);
    level
}

/// A hot loop compiled once per [`SimdLevel`]. `run` must be
/// `#[inline(always)]`, and so must everything it calls that should be
/// vectorised for the level: a function compiled for the baseline and not
/// inlined runs at the baseline. The kernels that need instructions of a
/// level explicitly take them from `isa`.
pub(crate) trait Kernel {
    type Output;
    fn run<I: Isa>(self, isa: I) -> Self::Output;
}

/// Runs `kernel` compiled for the active level.
#[inline(always)]
pub(crate) fn dispatch<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    match active_simd_level() {
        // SAFETY: `active_simd_level` is never above `SimdLevel::detected()`
        // (`limit_simd_level` clamps to it), which checked at run time that
        // the CPU has every feature `run_avx512` enables.
        SimdLevel::Avx512 => unsafe { run_avx512(kernel) },
        // SAFETY: as above, the CPU was seen to have every feature `run_avx2` enables.
        SimdLevel::Avx2 => unsafe { run_avx2(kernel) },
        SimdLevel::Portable => kernel.run(Portable),
    }
    #[cfg(not(target_arch = "x86_64"))]
    kernel.run(Portable)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn run_avx2<K: Kernel>(kernel: K) -> K::Output {
    kernel.run(Avx2(()))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx512cd,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn run_avx512<K: Kernel>(kernel: K) -> K::Output {
    kernel.run(Avx512(()))
}

/// The kernels that are written for one instruction set; [`Portable`]
/// holds the versions every CPU runs, which the others must match bit for
/// bit.
pub(crate) trait Isa: Copy {
    /// Whether [`Isa::enter_boxes`] and [`Isa::enter_quantised`] take rays
    /// whose range starts behind their origin (`PlaneRay::starts_behind`).
    /// The intrinsic kernels do not: for every other ray an exit is one
    /// product (`crate::slab::later_exit`), and a test of the flag in the
    /// kernel, once per node, cost more than the product saves (on the
    /// bunny, cachegrind: 1,113 instructions a ray before the fold, 1,075
    /// with it, 1,141 with the flag tested per node and the portable kernel
    /// inlined beside). Single-ray queries test it once per ray, before
    /// dispatching, and run such rays at the portable level
    /// (`WideBvh::traverse_portable`).
    const NODES_TAKE_RAYS_STARTING_BEHIND: bool;

    /// [`WideBoxes::enter`]: where one ray enters each of `W` boxes.
    fn enter_boxes<const W: usize>(self, boxes: &WideBoxes<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]);

    /// [`QuantisedNode::enter_portable`]: where one ray enters each of the
    /// `W` quantised boxes of a node.
    fn enter_quantised<const W: usize>(self, node: &QuantisedNode<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]);

    /// [`IntervalRay::enter_boxes`]: which of `W` boxes some ray of a
    /// packet may enter, tested once for the packet.
    fn enter_interval<const W: usize>(self, boxes: &WideBoxes<W>, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]);

    /// [`PacketRays::enter_box`]: which rays of a packet enter one box.
    fn enter_box_packet(
        self,
        near: [f32; 3],
        far: [f32; 3],
        rays: &PacketRays,
        t_max: &Lanes,
        active: u32,
    ) -> (u32, f32);

    /// [`PacketRays::enter_box_lanes`]: where each ray of a packet enters
    /// one box.
    fn enter_box_lanes(self, near: [f32; 3], far: [f32; 3], rays: &PacketRays, t_max: &Lanes) -> Lanes {
        rays.enter_box_lanes(near, far, t_max)
    }

    /// Whether packets test each triangle against all their rays at once
    /// ([`Isa::watertight_packet`]) rather than ray by ray: only where one
    /// instruction covers the sixteen rays.
    const PACKET_TRIANGLES: bool;

    /// [`WatertightPacket::intersect_portable`]: one triangle against a
    /// packet's rays.
    fn watertight_packet(self, packet: &WatertightPacket, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits;
}

/// Asks the CPU to start loading the `bytes` bytes at `data` into its
/// caches, for memory that traversal is about to visit (the children it
/// has just pushed); a hint that never changes what the program computes.
#[inline(always)]
pub(crate) fn prefetch<T>(data: &T, bytes: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let start = (data as *const T).cast::<i8>();
        for offset in (0..bytes).step_by(64) {
            // SAFETY: a prefetch never faults, whatever the address, and
            // neither reads nor writes anything the program can observe;
            // `wrapping_add` keeps the address computation defined.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (data, bytes);
}

/// The kernels in plain Rust (SSE at the x86-64-v2 baseline).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Portable;

impl Isa for Portable {
    const NODES_TAKE_RAYS_STARTING_BEHIND: bool = true;

    #[inline(always)]
    fn enter_boxes<const W: usize>(self, boxes: &WideBoxes<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        boxes.enter(ray, t_max)
    }

    #[inline(always)]
    fn enter_quantised<const W: usize>(self, node: &QuantisedNode<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        node.enter_portable(ray, t_max)
    }

    #[inline(always)]
    fn enter_interval<const W: usize>(self, boxes: &WideBoxes<W>, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
        ray.enter_boxes(boxes, t_max)
    }

    #[inline(always)]
    fn enter_box_packet(
        self,
        near: [f32; 3],
        far: [f32; 3],
        rays: &PacketRays,
        t_max: &Lanes,
        active: u32,
    ) -> (u32, f32) {
        rays.enter_box(near, far, t_max, active)
    }

    const PACKET_TRIANGLES: bool = false;

    #[inline(always)]
    fn watertight_packet(self, packet: &WatertightPacket, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits {
        packet.intersect_portable(t_max, corners)
    }
}

/// Proof that the CPU runs AVX2 and FMA: made only by `run_avx2`, which
/// `dispatch` calls after detecting those features.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2(());

/// Proof that the CPU runs AVX-512 (F, VL, BW, DQ, CD) and AVX2: made only
/// by `run_avx512`, which `dispatch` calls after detecting those features.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx512(());

#[cfg(target_arch = "x86_64")]
impl Isa for Avx2 {
    const NODES_TAKE_RAYS_STARTING_BEHIND: bool = false;

    #[inline(always)]
    fn enter_boxes<const W: usize>(self, boxes: &WideBoxes<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        debug_assert!(!ray.starts_behind, "see `Isa::NODES_TAKE_RAYS_STARTING_BEHIND`");
        if !W.is_multiple_of(8) {
            return boxes.enter(ray, t_max);
        }
        // SAFETY: an `Avx2` exists only where the CPU was seen to run AVX2
        // (see the type), the one requirement of calling a function with
        // `#[target_feature(enable = "avx2")]`.
        unsafe { enter_boxes_avx2(boxes, ray, t_max) }
    }

    #[inline(always)]
    fn enter_quantised<const W: usize>(self, node: &QuantisedNode<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        debug_assert!(!ray.starts_behind, "see `Isa::NODES_TAKE_RAYS_STARTING_BEHIND`");
        if !W.is_multiple_of(8) {
            return node.enter_portable(ray, t_max);
        }
        // SAFETY: as above, the CPU runs AVX2.
        unsafe { enter_quantised_avx2(node, ray, t_max) }
    }

    #[inline(always)]
    fn enter_interval<const W: usize>(self, boxes: &WideBoxes<W>, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
        if !W.is_multiple_of(8) {
            return ray.enter_boxes(boxes, t_max);
        }
        // SAFETY: as above, the CPU runs AVX2.
        unsafe { enter_interval_avx2(boxes, ray, t_max) }
    }

    #[inline(always)]
    fn enter_box_packet(
        self,
        near: [f32; 3],
        far: [f32; 3],
        rays: &PacketRays,
        t_max: &Lanes,
        active: u32,
    ) -> (u32, f32) {
        // SAFETY: as above, the CPU runs AVX2.
        unsafe { enter_box_packet_avx2(near, far, rays, t_max, active) }
    }

    /// Sixteen rays take two 256-bit registers a value: left ray by ray.
    const PACKET_TRIANGLES: bool = false;

    #[inline(always)]
    fn watertight_packet(self, packet: &WatertightPacket, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits {
        packet.intersect_portable(t_max, corners)
    }
}

#[cfg(target_arch = "x86_64")]
impl Isa for Avx512 {
    const NODES_TAKE_RAYS_STARTING_BEHIND: bool = false;

    /// Eight lanes fit a 256-bit register: the AVX2 kernel, which this
    /// level's CPUs run (`SimdLevel::detected` requires AVX2 for AVX-512).
    #[inline(always)]
    fn enter_boxes<const W: usize>(self, boxes: &WideBoxes<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        Avx2(()).enter_boxes(boxes, ray, t_max)
    }

    #[inline(always)]
    fn enter_quantised<const W: usize>(self, node: &QuantisedNode<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        Avx2(()).enter_quantised(node, ray, t_max)
    }

    /// As [`Avx512::enter_boxes`], the AVX2 kernel, with EVEX encodings
    /// and sixteen more registers where this level compiles it.
    #[inline(always)]
    fn enter_interval<const W: usize>(self, boxes: &WideBoxes<W>, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
        Avx2(()).enter_interval(boxes, ray, t_max)
    }

    #[inline(always)]
    fn enter_box_packet(
        self,
        near: [f32; 3],
        far: [f32; 3],
        rays: &PacketRays,
        t_max: &Lanes,
        active: u32,
    ) -> (u32, f32) {
        // SAFETY: an `Avx512` exists only where the CPU was seen to run AVX-512 F.
        unsafe { enter_box_packet_avx512(near, far, rays, t_max, active) }
    }

    #[inline(always)]
    fn enter_box_lanes(self, near: [f32; 3], far: [f32; 3], rays: &PacketRays, t_max: &Lanes) -> Lanes {
        // SAFETY: an `Avx512` exists only where the CPU was seen to run AVX-512 F.
        unsafe { enter_box_lanes_avx512(near, far, rays, t_max) }
    }

    const PACKET_TRIANGLES: bool = true;

    #[inline(always)]
    fn watertight_packet(self, packet: &WatertightPacket, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits {
        // SAFETY: an `Avx512` exists only where the CPU was seen to run AVX-512 F.
        unsafe { watertight_packet_avx512(packet, t_max, corners) }
    }
}

/// [`WatertightPacket::intersect_portable`] on all sixteen rays in 512-bit
/// registers: the same operations on the same operands in the same order,
/// lane by lane (products commute exactly, and `max_ps(a, b)` is
/// `a > b ? a : b`, as `arith`'s `max`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
fn watertight_packet_avx512(packet: &WatertightPacket, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits {
    use std::arch::x86_64::*;
    // SAFETY: each argument is a reference to sixteen `f32`s, valid for a
    // 64-byte load, and `Lanes` is 64-byte aligned.
    let load = |values: &Lanes| unsafe { _mm512_load_ps(values.0.as_ptr()) };
    let store = |value: __m512| {
        let mut lanes = Lanes([0.0; PACKET]);
        // SAFETY: `lanes` is sixteen `f32`s, 64-byte aligned, valid for a 64-byte store.
        unsafe { _mm512_store_ps(lanes.0.as_mut_ptr(), value) };
        lanes
    };
    let splat = |value: f32| _mm512_set1_ps(value);
    let add = |a, b| _mm512_add_ps(a, b);
    let sub = |a, b| _mm512_sub_ps(a, b);
    let mul = |a, b| _mm512_mul_ps(a, b);
    let abs = |a| _mm512_abs_ps(a);
    let max = |a, b| _mm512_max_ps(a, b);
    let origin = [load(&packet.origin[0]), load(&packet.origin[1]), load(&packet.origin[2])];
    let shear = [load(&packet.shear[0]), load(&packet.shear[1]), load(&packet.shear[2])];
    let [kx, ky, kz] = packet.axes;
    // `arith::watertight_shear` of the corners relative to each origin
    // (written out: array maps of closures were left as calls).
    let mut xs = [_mm512_setzero_ps(); 3];
    let mut ys = xs;
    let mut zs = xs;
    let mut heights = xs;
    for c in 0..3 {
        let corner = corners[c];
        let (rx, ry, rz) =
            (sub(splat(corner[kx]), origin[0]), sub(splat(corner[ky]), origin[1]), sub(splat(corner[kz]), origin[2]));
        xs[c] = sub(rx, mul(shear[0], rz));
        ys[c] = sub(ry, mul(shear[1], rz));
        zs[c] = mul(rz, shear[2]);
        heights[c] = rz;
    }
    // `arith::watertight_edges`.
    let uvw = [
        sub(mul(xs[2], ys[1]), mul(ys[2], xs[1])),
        sub(mul(xs[0], ys[2]), mul(ys[0], xs[2])),
        sub(mul(xs[1], ys[0]), mul(ys[1], xs[0])),
    ];
    // `arith::watertight_edge_bound`.
    let largest = |v: [__m512; 3]| max(max(abs(v[0]), abs(v[1])), abs(v[2]));
    let (x, y, z) = (largest(xs), largest(ys), largest(heights));
    let spread = mul(z, add(mul(x, abs(shear[1])), mul(y, abs(shear[0]))));
    let bound = add(mul(splat(32.0 * f32::EPSILON / 2.0), add(mul(x, y), spread)), splat(f32::from_bits(1 << 4)));
    let zero = _mm512_setzero_ps();
    let near_edge = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(abs(uvw[0]), bound)
        | _mm512_cmp_ps_mask::<_CMP_LE_OQ>(abs(uvw[1]), bound)
        | _mm512_cmp_ps_mask::<_CMP_LE_OQ>(abs(uvw[2]), bound);
    let negative = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(uvw[0], zero)
        | _mm512_cmp_ps_mask::<_CMP_LT_OQ>(uvw[1], zero)
        | _mm512_cmp_ps_mask::<_CMP_LT_OQ>(uvw[2], zero);
    let positive = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(uvw[0], zero)
        | _mm512_cmp_ps_mask::<_CMP_GT_OQ>(uvw[1], zero)
        | _mm512_cmp_ps_mask::<_CMP_GT_OQ>(uvw[2], zero);
    let one_sided = !(negative & positive);
    // `arith::watertight_det_and_scaled_t` and `arith::watertight_t_bound`.
    let det = add(add(uvw[0], uvw[1]), uvw[2]);
    let t_scaled = add(add(mul(uvw[0], zs[0]), mul(uvw[1], zs[1])), mul(uvw[2], zs[2]));
    let t_bound = mul(add(mul(splat(8.0 * f32::EPSILON / 2.0), abs(det)), mul(splat(3.0), bound)), largest(zs));
    let cancels = one_sided & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(abs(t_scaled), t_bound);
    let t = _mm512_div_ps(t_scaled, det);
    let infinity = splat(f32::INFINITY);
    let finite = |v: __m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(abs(v), infinity);
    let in_range = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, load(&packet.t_min))
        & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t, load(t_max))
        & finite(t);
    let hit = one_sided & _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(det, zero) & finite(det) & in_range;
    let rescan = near_edge | cancels;
    PacketHits {
        exact: (hit & !rescan) as u32,
        rescan: rescan as u32,
        t: store(t),
        beta_scaled: store(uvw[1]),
        gamma_scaled: store(uvw[2]),
        scale: store(det),
    }
}

/// [`crate::slab::later_exit`] on eight lanes: `max(to_far · ahead,
/// to_far · behind)`, with `_mm256_max_ps` taking its operands in the
/// order `Vec4::max` gives them, so that a NaN picks the same one.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn later_exit_avx2(
    to_far: std::arch::x86_64::__m256,
    ahead: std::arch::x86_64::__m256,
    behind: std::arch::x86_64::__m256,
) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    _mm256_max_ps(_mm256_mul_ps(to_far, ahead), _mm256_mul_ps(to_far, behind))
}

/// [`WideBoxes::enter`] eight lanes at a time, in 256-bit registers; the
/// same operations in the same order, lane by lane.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn enter_boxes_avx2<const W: usize>(boxes: &WideBoxes<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
    enter_planes_avx2::<W>(|plane, chunk| load_planes_avx2(boxes, plane, chunk), ray, t_max)
}

/// Row `plane` of `boxes`' planes, lanes `8 · chunk` to `8 · chunk + 7`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn load_planes_avx2<const W: usize>(boxes: &WideBoxes<W>, plane: usize, chunk: usize) -> std::arch::x86_64::__m256 {
    let lanes: &[f32; 8] = boxes.planes[plane][chunk * 8..chunk * 8 + 8].try_into().expect("eight lanes");
    // SAFETY: `lanes` is a reference to eight `f32`s, valid for a
    // 32-byte load, and 32-byte aligned: `WideBoxes` is, and each of
    // its rows is a multiple of eight lanes (32 bytes) long. (An
    // unaligned load would do, but LLVM's generic tuning splits those
    // in two unless it sees the alignment.)
    unsafe { std::arch::x86_64::_mm256_load_ps(lanes.as_ptr()) }
}

/// [`QuantisedNode::enter_portable`] eight lanes at a time: each plane's
/// steps widened to 32-bit integers, converted (exactly) and decoded with
/// the same product and sum, then the slab test of [`enter_boxes_avx2`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn enter_quantised_avx2<const W: usize>(node: &QuantisedNode<W>, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
    use std::arch::x86_64::*;
    let (origin, scale) = (node.origin(), node.scale());
    let load = |plane: usize, chunk: usize| {
        let steps: &[u8; 8] = node.steps(plane)[chunk * 8..chunk * 8 + 8].try_into().expect("eight lanes");
        // SAFETY: `steps` is a reference to eight bytes, valid for the
        // 8-byte load, which has no alignment requirement.
        let bytes = unsafe { _mm_loadl_epi64(steps.as_ptr().cast()) };
        let steps = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes));
        let axis = plane % 3;
        _mm256_add_ps(_mm256_set1_ps(origin[axis]), _mm256_mul_ps(steps, _mm256_set1_ps(scale[axis])))
    };
    enter_planes_avx2::<W>(load, ray, t_max)
}

/// The slab test of [`WideBoxes::enter`] on eight lanes at a time, whose
/// planes `load(plane, chunk)` gives: row `plane` of
/// [`WideBoxes::planes`], lanes `8 · chunk` to `8 · chunk + 7`.
///
/// Only for rays whose range starts at or after the origin
/// (`!ray.starts_behind`): their two exit inverses are equal, so an exit
/// is one product. Testing the flag here cost more than the second
/// product saves (see [`Isa::NODES_TAKE_RAYS_STARTING_BEHIND`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn enter_planes_avx2<const W: usize>(
    load: impl Fn(usize, usize) -> std::arch::x86_64::__m256,
    ray: &PlaneRay,
    t_max: f32,
) -> (u32, [f32; W]) {
    use std::arch::x86_64::*;
    slab_test_avx2(load, ray.near, ray.t_min, t_max, |axis, near, far| {
        let origin = _mm256_set1_ps(ray.origin[axis]);
        let inv = _mm256_set1_ps(ray.inv_direction[axis]);
        // One product for the exit: the two exit inverses are equal for the
        // rays this kernel takes, and so are the bits (`crate::slab::later_exit`).
        let exit_inv = _mm256_set1_ps(ray.inv_exit[axis]);
        (_mm256_mul_ps(_mm256_sub_ps(near, origin), inv), _mm256_mul_ps(_mm256_sub_ps(far, origin), exit_inv))
    })
}

/// The slab test's combination of distances, eight boxes at a time, as
/// [`crate::simd::boxes::enter_planes`] combines four: `distances(axis,
/// near, far)` gives the distances along `axis` to eight boxes' near
/// planes and (enlarged) far planes, which `load(plane, chunk)` gives,
/// `near_planes[axis]` indexing the near ones. Returns each box's entry
/// distance within `[t_min, t_max]`, or +∞, and the mask of the boxes
/// entered.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn slab_test_avx2<const W: usize>(
    load: impl Fn(usize, usize) -> std::arch::x86_64::__m256,
    near_planes: [usize; 3],
    t_min: f32,
    t_max: f32,
    distances: impl Fn(
        usize,
        std::arch::x86_64::__m256,
        std::arch::x86_64::__m256,
    ) -> (std::arch::x86_64::__m256, std::arch::x86_64::__m256),
) -> (u32, [f32; W]) {
    use std::arch::x86_64::*;
    let mut entries = [f32::INFINITY; W];
    let mut mask = 0;
    for chunk in 0..W / 8 {
        let mut enter = _mm256_set1_ps(t_min);
        let mut exit = _mm256_set1_ps(t_max);
        for (axis, flip) in FAR_OF_NEAR.into_iter().enumerate() {
            let near = load(near_planes[axis], chunk);
            let far = load(near_planes[axis] ^ flip, chunk);
            let (t_near, t_far) = distances(axis, near, far);
            // `max(a, b)` is `a > b ? a : b`: a NaN in `a` leaves the bound.
            enter = _mm256_max_ps(t_near, enter);
            exit = _mm256_min_ps(t_far, exit);
        }
        let infinity = _mm256_set1_ps(f32::INFINITY);
        let entered =
            _mm256_and_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit), _mm256_cmp_ps::<_CMP_LT_OQ>(enter, infinity));
        let out: &mut [f32; 8] = (&mut entries[chunk * 8..chunk * 8 + 8]).try_into().expect("eight lanes");
        // SAFETY: `out` is a mutable reference to eight `f32`s, valid for an
        // unaligned 32-byte store.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), _mm256_blendv_ps(infinity, enter, entered)) };
        mask |= (_mm256_movemask_ps(entered) as u32) << (chunk * 8);
    }
    (mask, entries)
}

/// [`IntervalRay::enter_boxes`] eight boxes at a time, in 256-bit
/// registers: the same operations in the same order, lane by lane, except
/// that the side of the origin a plane lies on is read from the sign bit
/// of the difference flipped by the direction's sign, where the portable
/// kernel multiplies by ±1 (an exact product: the comparisons agree, NaN
/// and ±0 included).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn enter_interval_avx2<const W: usize>(boxes: &WideBoxes<W>, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
    use std::arch::x86_64::*;
    let load = |plane: usize, chunk: usize| load_planes_avx2(boxes, plane, chunk);
    let zero = _mm256_setzero_ps();
    slab_test_avx2(load, ray.near, ray.t_min, t_max, |axis, near, far| {
        // -0.0 for a negative direction, +0.0 for a positive one.
        let sign = _mm256_set1_ps(if ray.sign[axis] < 0.0 { -0.0 } else { 0.0 });
        let to_near = _mm256_sub_ps(near, _mm256_set1_ps(ray.origin_ahead[axis]));
        let along = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_xor_ps(to_near, sign), zero);
        let inv = _mm256_blendv_ps(_mm256_set1_ps(ray.inv_big[axis]), _mm256_set1_ps(ray.inv_small[axis]), along);
        let to_far = _mm256_sub_ps(far, _mm256_set1_ps(ray.origin_behind[axis]));
        let backwards = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_xor_ps(to_far, sign), zero);
        let pick = |small: f32, big: f32| _mm256_blendv_ps(_mm256_set1_ps(big), _mm256_set1_ps(small), backwards);
        let ahead = pick(ray.exit_small[axis], ray.exit_big[axis]);
        let behind = pick(ray.exit_behind_small[axis], ray.exit_behind_big[axis]);
        (_mm256_mul_ps(to_near, inv), later_exit_avx2(to_far, ahead, behind))
    })
}

/// [`PacketRays::enter_box`] eight rays at a time, in 256-bit registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn enter_box_packet_avx2(near: [f32; 3], far: [f32; 3], rays: &PacketRays, t_max: &Lanes, active: u32) -> (u32, f32) {
    use std::arch::x86_64::*;
    let load = |values: &Lanes, chunk: usize| {
        let lanes: &[f32; 8] = values.0[chunk * 8..chunk * 8 + 8].try_into().expect("eight lanes");
        // SAFETY: `lanes` is a reference to eight `f32`s, valid for a
        // 32-byte load, and 32-byte aligned: `Lanes` is 64-byte aligned and
        // `chunk * 8` lanes are a multiple of 32 bytes.
        unsafe { _mm256_load_ps(lanes.as_ptr()) }
    };
    let infinity = _mm256_set1_ps(f32::INFINITY);
    let mut earliest = infinity;
    let mut mask = 0;
    for chunk in 0..PACKET / 8 {
        let mut enter = load(&rays.t_min, chunk);
        let mut exit = load(t_max, chunk);
        for axis in 0..3 {
            let origin = load(&rays.origin[axis], chunk);
            let inv = load(&rays.inv_direction[axis], chunk);
            let t_near = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(near[axis]), origin), inv);
            let to_far = _mm256_sub_ps(_mm256_set1_ps(far[axis]), origin);
            let t_far =
                later_exit_avx2(to_far, load(&rays.inv_exit[axis], chunk), load(&rays.inv_exit_behind[axis], chunk));
            enter = _mm256_max_ps(t_near, enter);
            exit = _mm256_min_ps(t_far, exit);
        }
        let entered =
            _mm256_and_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit), _mm256_cmp_ps::<_CMP_LT_OQ>(enter, infinity));
        earliest = _mm256_min_ps(earliest, _mm256_blendv_ps(infinity, enter, entered));
        mask |= (_mm256_movemask_ps(entered) as u32) << (chunk * 8);
    }
    let mut lanes = [0.0f32; 8];
    // SAFETY: `lanes` is eight `f32`s, valid for an unaligned 32-byte store.
    unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), earliest) };
    (mask & active, lanes.iter().fold(f32::INFINITY, |a, &b| a.min(b)))
}

/// The robust slab test of one box for all sixteen rays of a packet in
/// 512-bit registers, as [`PacketRays::enter_box`] computes it: the rays
/// that enter the box, and where each enters (valid in those lanes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
fn box_packet_avx512(
    near: [f32; 3],
    far: [f32; 3],
    rays: &PacketRays,
    t_max: &Lanes,
) -> (std::arch::x86_64::__mmask16, std::arch::x86_64::__m512) {
    use std::arch::x86_64::*;
    // SAFETY: each argument is a reference to sixteen `f32`s, valid for a
    // 64-byte load, and `Lanes` is 64-byte aligned.
    let load = |values: &Lanes| unsafe { _mm512_load_ps(values.0.as_ptr()) };
    let mut enter = load(&rays.t_min);
    let mut exit = load(t_max);
    for axis in 0..3 {
        let origin = load(&rays.origin[axis]);
        let inv = load(&rays.inv_direction[axis]);
        let t_near = _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(near[axis]), origin), inv);
        let to_far = _mm512_sub_ps(_mm512_set1_ps(far[axis]), origin);
        // `crate::slab::later_exit`, as in `later_exit_avx2`.
        let ahead = _mm512_mul_ps(to_far, load(&rays.inv_exit[axis]));
        let t_far = _mm512_max_ps(ahead, _mm512_mul_ps(to_far, load(&rays.inv_exit_behind[axis])));
        enter = _mm512_max_ps(t_near, enter);
        exit = _mm512_min_ps(t_far, exit);
    }
    let entered = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit)
        & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(enter, _mm512_set1_ps(f32::INFINITY));
    (entered, enter)
}

/// [`PacketRays::enter_box`] on all sixteen rays in one 512-bit register.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
fn enter_box_packet_avx512(near: [f32; 3], far: [f32; 3], rays: &PacketRays, t_max: &Lanes, active: u32) -> (u32, f32) {
    use std::arch::x86_64::*;
    let (entered, enter) = box_packet_avx512(near, far, rays, t_max);
    // The masked reduction of no lanes gives f32::MAX; the portable kernel's +∞ is kept.
    let earliest = if entered == 0 { f32::INFINITY } else { _mm512_mask_reduce_min_ps(entered, enter) };
    (entered as u32 & active, earliest)
}

/// [`PacketRays::enter_box_lanes`] on all sixteen rays in one 512-bit register.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
fn enter_box_lanes_avx512(near: [f32; 3], far: [f32; 3], rays: &PacketRays, t_max: &Lanes) -> Lanes {
    use std::arch::x86_64::*;
    let (entered, enter) = box_packet_avx512(near, far, rays, t_max);
    let mut entries = Lanes([0.0; PACKET]);
    // SAFETY: `entries` is sixteen `f32`s, 64-byte aligned, valid for a 64-byte store.
    unsafe {
        _mm512_store_ps(entries.0.as_mut_ptr(), _mm512_mask_blend_ps(entered, _mm512_set1_ps(f32::INFINITY), enter))
    };
    entries
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slab::BoxRay;
    use rtgi_math::{Ray, Rng, Vec3};

    /// Runs the box kernels of the active level on one case, beside the
    /// portable ones: node boxes for one ray, and one box for a packet.
    struct Compare<'a> {
        boxes: &'a WideBoxes<8>,
        ray: &'a PlaneRay,
        packet: &'a PacketRays,
        t_max: f32,
        packet_t_max: &'a Lanes,
        quantised: &'a QuantisedNode<8>,
        interval: &'a IntervalRay,
    }

    type Entered = (u32, [f32; 8]);

    impl Kernel for Compare<'_> {
        type Output =
            ((Entered, Entered), (Entered, Entered), (Entered, Entered), Vec<((u32, f32), (u32, f32), Lanes, Lanes)>);

        #[inline(always)]
        fn run<I: Isa>(self, isa: I) -> Self::Output {
            let node = (
                isa.enter_boxes(self.boxes, self.ray, self.t_max),
                Portable.enter_boxes(self.boxes, self.ray, self.t_max),
            );
            let quantised = (
                isa.enter_quantised(self.quantised, self.ray, self.t_max),
                Portable.enter_quantised(self.quantised, self.ray, self.t_max),
            );
            let interval = (
                isa.enter_interval(self.boxes, self.interval, self.t_max),
                Portable.enter_interval(self.boxes, self.interval, self.t_max),
            );
            let packets = (0..8)
                .map(|lane| {
                    let planes = &self.boxes.planes;
                    let near = [0, 1, 2].map(|axis| planes[self.packet.near[axis]][lane]);
                    let far = [0, 1, 2].map(|axis| planes[self.packet.near[axis] ^ FAR_OF_NEAR[axis]][lane]);
                    (
                        isa.enter_box_packet(near, far, self.packet, self.packet_t_max, 0xffff),
                        Portable.enter_box_packet(near, far, self.packet, self.packet_t_max, 0xffff),
                        isa.enter_box_lanes(near, far, self.packet, self.packet_t_max),
                        Portable.enter_box_lanes(near, far, self.packet, self.packet_t_max),
                    )
                })
                .collect();
            (node, quantised, interval, packets)
        }
    }

    /// The intrinsic kernels of every level the CPU has compute the bits
    /// of the portable ones (the interval ray's included), on boxes and
    /// rays with zeros, ±0 direction components, origins on box planes
    /// and NaN-producing `0 · ∞`.
    #[test]
    fn every_level_computes_the_portable_kernels_bits() {
        let detected = SimdLevel::detected();
        let mut rng = Rng::new(41, 7);
        let coordinate = |rng: &mut Rng| match rng.next_u32() % 6 {
            0 => 0.0,
            1 => 1.0,
            2 => -0.0,
            _ => rng.next_f32() * 8.0 - 4.0,
        };
        for _ in 0..3000 {
            let mut boxes = WideBoxes::<8>::EMPTY;
            for lane in 0..7 {
                let (a, b) = ([0; 3].map(|_| coordinate(&mut rng)), [0; 3].map(|_| coordinate(&mut rng)));
                boxes.set(
                    lane,
                    Vec3::from(a).min(Vec3::from(b)).to_array(),
                    Vec3::from(a).max(Vec3::from(b)).to_array(),
                );
            }
            let quantised = QuantisedNode::of_boxes(&boxes, 7);
            let direction = Vec3::from([0; 3].map(|_| coordinate(&mut rng)));
            let direction = if direction == Vec3::ZERO { Vec3::new(-0.0, 0.5, 1.0) } else { direction };
            let rays: Vec<Ray> =
                (0..PACKET).map(|_| Ray::new(Vec3::from([0; 3].map(|_| coordinate(&mut rng))), direction)).collect();
            let packet = PacketRays::new(&rays).expect("equal directions are coherent");
            // The interval ray of rays whose directions differ a little
            // (same signs, zeros kept), so that its inverses span a range.
            let spread: Vec<Ray> = rays
                .iter()
                .map(|ray| {
                    let scale = Vec3::from([0; 3].map(|_| 1.0 + rng.next_f32() * 0.02));
                    Ray::new(ray.origin, ray.direction * scale)
                })
                .collect();
            let interval = IntervalRay::new(&PacketRays::new(&spread).expect("directions 1° apart are coherent"));
            let ray = PlaneRay::new(&BoxRay::new(&rays[0]));
            let t_max = if rng.next_u32().is_multiple_of(2) { f32::INFINITY } else { rng.next_f32() * 4.0 };
            let packet_t_max = Lanes(std::array::from_fn(|_| rng.next_f32() * 8.0));
            for &level in SimdLevel::ALL.iter().filter(|&&level| level <= detected) {
                limit_simd_level(level);
                let compare = Compare {
                    boxes: &boxes,
                    ray: &ray,
                    packet: &packet,
                    t_max,
                    packet_t_max: &packet_t_max,
                    quantised: &quantised,
                    interval: &interval,
                };
                let (node, node_quantised, node_interval, packets) = dispatch(compare);
                for (ours, portable) in [node, node_quantised, node_interval] {
                    assert_eq!(ours.0, portable.0, "{level}");
                    assert_eq!(ours.1.map(f32::to_bits), portable.1.map(f32::to_bits), "{level}");
                }
                for (ours, portable, ours_lanes, portable_lanes) in packets {
                    assert_eq!(ours.0, portable.0, "{level}");
                    assert_eq!(ours.1.to_bits(), portable.1.to_bits(), "{level}");
                    assert_eq!(ours_lanes.0.map(f32::to_bits), portable_lanes.0.map(f32::to_bits), "{level}");
                }
            }
        }
        limit_simd_level(detected);
    }
}
