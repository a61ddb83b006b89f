//! Intel Embree 3 as a backend (feature `embree`): a peer to measure our
//! structures against, not a structure held to the exactness contract.
//!
//! Embree answers the same queries through the same [`Accel`] trait, so it
//! can be swapped in anywhere ours are, but its answers are its own: its
//! triangle test is not watertight by default and differs from ours in the
//! last bits of `t`, `beta` and `gamma`, it breaks ties between triangles
//! hit at the same `t` in traversal order rather than by the lowest index,
//! and it treats rays that graze edges and boxes differently. The crate's
//! exactness tests therefore leave it out ([`crate::AccelKind::PEERS`]).
//!
//! This is the one file of the workspace allowed to use `unsafe`: it calls
//! Embree's C API (`embree::sys`) directly, because the `embree` crate's
//! safe `Scene` borrows its `Device` and is neither `Send` nor `Sync`,
//! while an [`Accel`] must own its data and be shared between threads.
#![allow(unsafe_code)]

use std::any::Any;
use std::ffi::{CString, c_int, c_void};
use std::fmt;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::time::Instant;

use ::embree::sys;
use rtgi_math::{Ray, Vec3};

use crate::{Accel, BuildStats, Hit, TraversalCounters, TriangleSource, is_hittable};

/// Embree's "no geometry hit" marker (`RTC_INVALID_GEOMETRY_ID`).
const INVALID_ID: u32 = u32::MAX;

/// The largest coordinate Embree accepts in a ray's origin and direction
/// (`FLT_LARGE` in its `kernels/common/ray.h`); builds with assertions
/// abort on rays beyond it.
const EMBREE_LARGEST: f32 = 1.844e18;

/// Whether Embree can trace `ray`: a valid ray ([`Ray::is_valid`]) whose
/// origin and direction lie within Embree's range.
fn traceable(ray: &Ray) -> bool {
    ray.is_valid()
        && ray.origin.abs().max_element() <= EMBREE_LARGEST
        && ray.direction.abs().max_element() <= EMBREE_LARGEST
}

/// The ray as Embree takes it, and how much Embree's distances fall short
/// of ours. Embree requires `tnear ≥ 0` (its builds with assertions abort
/// otherwise), so a range that starts behind the origin is given from a
/// moved origin `origin + t_min·direction` over `[0, t_max − t_min]`, and
/// Embree's distances are `t_min` short. The moved origin is rounded, so
/// those answers are near ours rather than exact, as a peer's may be.
fn embree_view(ray: &Ray) -> (Ray, f32) {
    if ray.t_min < 0.0 {
        let moved = ray.origin + ray.t_min * ray.direction;
        (Ray::with_range(moved, ray.direction, 0.0, ray.t_max - ray.t_min), ray.t_min)
    } else {
        (*ray, 0.0)
    }
}

/// The build quality of every scene: Embree's default, the one its own
/// benchmarks of static scenes use.
const BUILD_QUALITY: sys::RTCBuildQuality = sys::RTCBuildQuality::MEDIUM;
/// [`BUILD_QUALITY`] in words, for the records of comparisons.
const BUILD_QUALITY_NAME: &str = "medium";

/// Rays per packet of the batch queries (`rtcIntersect16`, `rtcOccluded16`).
const PACKET: usize = 16;

/// Why Embree could not build a scene: the step that failed and Embree's
/// error code (out of memory, an unsupported CPU, ...).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmbreeError {
    step: &'static str,
    code: String,
}

impl EmbreeError {
    fn new(step: &'static str, code: sys::RTCError) -> Self {
        Self { step, code: format!("{code:?}") }
    }
}

impl fmt::Display for EmbreeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Embree could not {}: error {}", self.step, self.code)
    }
}

impl std::error::Error for EmbreeError {}

/// An Embree 3 device and the committed scene of one triangle mesh,
/// queried through [`Accel`].
///
/// - Hits name triangles by their index in the input, as ours do: Embree
///   is given only the triangles for which [`is_hittable`] holds, and an
///   index table maps its primitive IDs back; the others are counted in
///   [`BuildStats::excluded_triangles`]. `beta` and `gamma` are Embree's
///   `u` and `v`, the barycentrics of the second and third corners.
/// - Invalid rays ([`Ray::is_valid`]) hit nothing, as with our structures,
///   and so do rays with a coordinate of origin or direction beyond
///   1.844e18, which Embree does not accept (it asserts on them).
/// - The counted queries count the ray only: Embree does not report the
///   nodes it visits or the triangles it tests, so those counters stay 0.
/// - The filtered queries pass the filter to Embree's intersection-context
///   filter callback, which rejects hits during traversal: the answer is
///   the closest (or any) hit the filter accepts, as with ours.
/// - The batch queries trace packets of 16 rays (`rtcIntersect16`,
///   `rtcOccluded16`) with the coherent-ray hint. Embree's packet kernels
///   may differ from its single-ray kernels in the last bits of a hit and
///   at ties, so for this backend a batch agrees with the single-ray
///   queries to rounding, not bit for bit.
/// - The build uses Embree's default (medium) quality and Embree's own
///   threads, as many as the calling rayon pool has
///   (`rayon::current_num_threads`), so `rtgi bench`'s one-thread build
///   column means one thread here too.
pub struct EmbreeBackend {
    device: sys::RTCDevice,
    /// Null until the scene is created (and on the error paths of `new`).
    scene: sys::RTCScene,
    /// Input index of each of Embree's primitives.
    ids: Vec<u32>,
    stats: BuildStats,
    /// Bytes Embree holds, summed by its memory monitor callback. Boxed so
    /// that its address stays fixed; released only after the device.
    memory: Box<AtomicIsize>,
}

// SAFETY: the device and scene handles are reference-counted objects that
// Embree allows any thread to use and release: nothing in them is tied to
// the thread that created them. After `rtcCommitScene` the scene is never
// modified again (no method takes `&mut self`), and Embree documents
// queries on a committed scene (`rtcIntersect*`, `rtcOccluded*`) as
// thread-safe, which is what sharing `&EmbreeBackend` across threads
// (`Sync`) allows; every query gets its own ray and context on its own
// stack. The memory counter is atomic.
unsafe impl Send for EmbreeBackend {}
// SAFETY: see `Send` above: after commit, concurrent queries on one scene
// are thread-safe by Embree's API contract, and `&self` offers nothing else.
unsafe impl Sync for EmbreeBackend {}

impl fmt::Debug for EmbreeBackend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("EmbreeBackend").field("stats", &self.stats).finish_non_exhaustive()
    }
}

impl Drop for EmbreeBackend {
    fn drop(&mut self) {
        if !self.scene.is_null() {
            // SAFETY: `scene` is the handle `rtcNewScene` returned, released
            // once, here; no query can be running as we hold `&mut self`.
            unsafe { sys::rtcReleaseScene(self.scene) };
        }
        // SAFETY: `device` is the non-null handle `rtcNewDevice` returned
        // (checked in `new`), released once, after the scene that refers
        // to it. The memory monitor it calls points into `self.memory`,
        // which is dropped only after this function returns.
        unsafe { sys::rtcReleaseDevice(self.device) };
    }
}

/// Embree's memory monitor: adds the bytes it allocates (positive) and
/// frees (negative) to the counter it was registered with.
unsafe extern "C" fn count_memory(counter: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: the callback is registered with a pointer to the backend's
    // boxed `AtomicIsize`, which outlives the device (see `Drop`); only
    // shared access is taken, and the counter is atomic because Embree's
    // build threads call this concurrently.
    let counter = unsafe { &*counter.cast::<AtomicIsize>() };
    counter.fetch_add(bytes, Ordering::Relaxed);
    true
}

impl EmbreeBackend {
    /// Builds an Embree scene over the hittable triangles ([`is_hittable`])
    /// of `triangles` (a soup, an [`crate::IndexedMesh`] or any
    /// [`TriangleSource`]); the others are counted in
    /// [`BuildStats::excluded_triangles`] and never hit.
    ///
    /// # Errors
    /// If Embree fails to create its device or to build the scene (out of
    /// memory, an unsupported CPU).
    pub fn new(triangles: &(impl TriangleSource + ?Sized)) -> Result<Self, EmbreeError> {
        Self::build(triangles, false)
    }

    /// As [`EmbreeBackend::new`], with Embree's robust traversal
    /// (`RTC_SCENE_FLAG_ROBUST`), which avoids optimisations that can miss
    /// boxes rays graze: the counterpart of our robust slab test, to tell
    /// how much of a difference in speed is the price of robustness.
    ///
    /// # Errors
    /// As [`EmbreeBackend::new`].
    pub fn robust(triangles: &(impl TriangleSource + ?Sized)) -> Result<Self, EmbreeError> {
        Self::build(triangles, true)
    }

    fn build(triangles: &(impl TriangleSource + ?Sized), robust: bool) -> Result<Self, EmbreeError> {
        let start = Instant::now();
        // Embree gets a soup of its own: its buffers are filled from it below.
        let (kept, ids): (Vec<[Vec3; 3]>, Vec<u32>) =
            (0..triangles.len()).map(|i| (triangles.corners(i), i as u32)).filter(|(t, _)| is_hittable(t)).unzip();
        let config = CString::new(format!("threads={}", rayon::current_num_threads()))
            .expect("a decimal number holds no NUL byte");
        // SAFETY: `config` is a NUL-terminated string that outlives the call.
        let device = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if device.is_null() {
            // SAFETY: with a null device, Embree returns the error of the
            // last failed device creation on this thread.
            return Err(EmbreeError::new("create a device", unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) }));
        }
        let memory = Box::new(AtomicIsize::new(0));
        let mut backend = Self { device, scene: std::ptr::null_mut(), ids, stats: BuildStats::default(), memory };
        let counter: *const AtomicIsize = &*backend.memory;
        // SAFETY: `device` is valid; the counter outlives it (see `Drop`)
        // and `count_memory` only reads through the pointer atomically.
        unsafe { sys::rtcSetDeviceMemoryMonitorFunction(device, Some(count_memory), counter as *mut c_void) };
        backend.commit(&kept, robust)?;
        let embree_bytes = usize::try_from(backend.memory.load(Ordering::Relaxed)).unwrap_or(0);
        backend.stats = BuildStats {
            variant: "embree".into(),
            triangles: triangles.len(),
            excluded_triangles: triangles.len() - kept.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            memory_bytes: embree_bytes + std::mem::size_of_val(backend.ids.as_slice()),
            ..BuildStats::default()
        };
        Ok(backend)
    }

    /// The Embree library this backend calls and how it builds: "Embree
    /// 3.13.5, build quality medium": what a comparison with it must record.
    ///
    /// # Errors
    /// If Embree cannot create a device (an unsupported CPU).
    pub fn library() -> Result<String, EmbreeError> {
        let config = CString::new("threads=1").expect("no NUL byte");
        // SAFETY: `config` is a NUL-terminated string that outlives the call.
        let device = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if device.is_null() {
            // SAFETY: with a null device, Embree returns the error of the
            // last failed device creation on this thread.
            return Err(EmbreeError::new("create a device", unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) }));
        }
        // SAFETY: `device` is the valid handle just created; the properties
        // are plain integers; the device is released once, here.
        let [major, minor, patch] = unsafe {
            let version = [
                sys::RTCDeviceProperty::VERSION_MAJOR,
                sys::RTCDeviceProperty::VERSION_MINOR,
                sys::RTCDeviceProperty::VERSION_PATCH,
            ]
            .map(|property| sys::rtcGetDeviceProperty(device, property));
            sys::rtcReleaseDevice(device);
            version
        };
        Ok(format!("Embree {major}.{minor}.{patch}, build quality {BUILD_QUALITY_NAME}"))
    }

    /// Creates, fills and commits the scene: one triangle geometry whose
    /// primitive `i` is `kept[i]` (three vertices of its own, no sharing).
    fn commit(&mut self, kept: &[[Vec3; 3]], robust: bool) -> Result<(), EmbreeError> {
        let device = self.device;
        let check = |step: &'static str| {
            // SAFETY: `device` is a valid device handle (checked in `new`).
            match unsafe { sys::rtcGetDeviceError(device) } {
                sys::RTCError::NONE => Ok(()),
                code => Err(EmbreeError::new(step, code)),
            }
        };
        // SAFETY: `device` is valid; a null result is checked below.
        self.scene = unsafe { sys::rtcNewScene(device) };
        if self.scene.is_null() {
            return Err(check("create a scene")
                .err()
                .unwrap_or(EmbreeError::new("create a scene", sys::RTCError::UNKNOWN)));
        }
        // SAFETY: `scene` is valid and not yet committed. The context
        // filter flag lets the filtered queries pass a filter in their
        // intersection context; unfiltered queries pass none. The robust
        // flag is asked for by `robust`. Medium is
        // Embree's default build quality, set to say so.
        unsafe {
            let flags = sys::RTCSceneFlags::CONTEXT_FILTER_FUNCTION;
            let flags = if robust { sys::RTCSceneFlags(flags.0 | sys::RTCSceneFlags::ROBUST.0) } else { flags };
            sys::rtcSetSceneFlags(self.scene, flags);
            sys::rtcSetSceneBuildQuality(self.scene, BUILD_QUALITY);
        }
        if !kept.is_empty() {
            self.attach_triangles(kept)?;
        }
        check("prepare the scene")?;
        // SAFETY: `scene` is valid and every attached geometry committed.
        unsafe { sys::rtcCommitScene(self.scene) };
        check("build the scene")
    }

    /// Attaches one committed triangle geometry holding `kept` (not empty).
    fn attach_triangles(&mut self, kept: &[[Vec3; 3]]) -> Result<(), EmbreeError> {
        let error = |step: &'static str| {
            // SAFETY: `self.device` is a valid device handle.
            let code = unsafe { sys::rtcGetDeviceError(self.device) };
            EmbreeError::new(step, if code == sys::RTCError::NONE { sys::RTCError::UNKNOWN } else { code })
        };
        // SAFETY: `device` is valid; a null result is checked below.
        let geometry = unsafe { sys::rtcNewGeometry(self.device, sys::RTCGeometryType::TRIANGLE) };
        if geometry.is_null() {
            return Err(error("create a triangle geometry"));
        }
        // SAFETY: `geometry` is a valid triangle geometry. Embree allocates
        // each buffer for `item count` items of `stride` bytes, 16-byte
        // aligned and padded so that it may read 16 bytes at the last
        // vertex; a null pointer (allocation failure) is checked before use.
        let (vertices, indices) = unsafe {
            (
                sys::rtcSetNewGeometryBuffer(
                    geometry,
                    sys::RTCBufferType::VERTEX,
                    0,
                    sys::RTCFormat::FLOAT3,
                    16,
                    3 * kept.len(),
                ),
                sys::rtcSetNewGeometryBuffer(
                    geometry,
                    sys::RTCBufferType::INDEX,
                    0,
                    sys::RTCFormat::UINT3,
                    12,
                    kept.len(),
                ),
            )
        };
        if vertices.is_null() || indices.is_null() {
            // SAFETY: `geometry` is valid and released once, here.
            unsafe { sys::rtcReleaseGeometry(geometry) };
            return Err(error("allocate the triangle buffers"));
        }
        // SAFETY: the buffers were just allocated by Embree for exactly
        // these many items of these strides, suitably aligned for `f32` and
        // `u32`, and nothing else refers to them until the geometry is
        // committed; the slices end before that.
        let (vertices, indices) = unsafe {
            (
                std::slice::from_raw_parts_mut(vertices.cast::<[f32; 4]>(), 3 * kept.len()),
                std::slice::from_raw_parts_mut(indices.cast::<[u32; 3]>(), kept.len()),
            )
        };
        for (i, (triangle, (corners, index))) in
            kept.iter().zip(vertices.chunks_exact_mut(3).zip(indices.iter_mut())).enumerate()
        {
            for (corner, vertex) in triangle.iter().zip(corners) {
                *vertex = [corner.x, corner.y, corner.z, 0.0];
            }
            let first = 3 * i as u32;
            *index = [first, first + 1, first + 2];
        }
        // SAFETY: `geometry` and `scene` are valid; the scene keeps its own
        // reference to the geometry, so ours is released after attaching.
        unsafe {
            sys::rtcCommitGeometry(geometry);
            sys::rtcAttachGeometry(self.scene, geometry);
            sys::rtcReleaseGeometry(geometry);
        }
        Ok(())
    }

    /// Our hit from Embree's answer for primitive `prim_id`.
    fn hit(&self, t: f32, prim_id: u32, u: f32, v: f32) -> Hit {
        Hit { t, triangle: self.ids[prim_id as usize], beta: u, gamma: v }
    }

    /// The closest hit, with `filter` (or none) in the intersection context.
    fn closest(&self, ray: &Ray, filter: Option<&dyn Fn(u32, f32, f32) -> bool>) -> Option<Hit> {
        let (ray, shift) = embree_view(ray);
        if !traceable(&ray) {
            return None;
        }
        let mut context = FilterContext::new(sys::RTCIntersectContextFlags::INCOHERENT, filter, &self.ids);
        let mut ray_hit = sys::RTCRayHit { ray: embree_ray(&ray), hit: no_hit() };
        let context_pointer: *mut FilterContext = &mut context;
        // SAFETY: the scene is committed and only read; `context_pointer`
        // points to a live `FilterContext` whose first field is the
        // `RTCIntersectContext` Embree expects (`repr(C)`), so the filter
        // callback may cast it back; `ray_hit` is a valid, 16-byte aligned
        // ray and hit that Embree writes the answer into.
        unsafe { sys::rtcIntersect1(self.scene, context_pointer.cast(), &mut ray_hit) };
        context.rethrow();
        (ray_hit.hit.geomID != INVALID_ID)
            .then(|| self.hit(ray_hit.ray.tfar + shift, ray_hit.hit.primID, ray_hit.hit.u, ray_hit.hit.v))
    }

    /// Whether anything is hit, with `filter` (or none) in the context.
    fn any(&self, ray: &Ray, filter: Option<&dyn Fn(u32, f32, f32) -> bool>) -> bool {
        let (ray, _) = embree_view(ray);
        if !traceable(&ray) {
            return false;
        }
        let mut context = FilterContext::new(sys::RTCIntersectContextFlags::INCOHERENT, filter, &self.ids);
        let mut embree_ray = embree_ray(&ray);
        let context_pointer: *mut FilterContext = &mut context;
        // SAFETY: as in `closest`; Embree sets `tfar` to -∞ on a hit.
        unsafe { sys::rtcOccluded1(self.scene, context_pointer.cast(), &mut embree_ray) };
        context.rethrow();
        embree_ray.tfar == f32::NEG_INFINITY
    }

    /// Closest hits of `rays` in packets of 16, with `filter` (or none) in the context.
    fn closest_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>], filter: Option<&dyn Fn(u32, f32, f32) -> bool>) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        let mut context = FilterContext::new(sys::RTCIntersectContextFlags::COHERENT, filter, &self.ids);
        for (rays, hits) in rays.chunks(PACKET).zip(hits.chunks_mut(PACKET)) {
            let valid = ValidMask::of(rays);
            hits.fill(None);
            if !valid.any() {
                continue;
            }
            let mut packet = sys::RTCRayHit16 {
                ray: packet_rays(rays),
                hit: sys::RTCHit16 {
                    Ng_x: [0.0; PACKET],
                    Ng_y: [0.0; PACKET],
                    Ng_z: [0.0; PACKET],
                    u: [0.0; PACKET],
                    v: [0.0; PACKET],
                    primID: [INVALID_ID; PACKET],
                    geomID: [INVALID_ID; PACKET],
                    instID: [[INVALID_ID; PACKET]],
                },
            };
            let context_pointer: *mut FilterContext = &mut context;
            // SAFETY: the scene is committed and only read; `valid` and
            // `packet` are 64-byte aligned as `rtcIntersect16` requires
            // (`repr(align(64))`) and live across the call; the context is
            // live and `repr(C)` with Embree's context first, as in `closest`.
            unsafe { sys::rtcIntersect16(valid.0.as_ptr(), self.scene, context_pointer.cast(), &mut packet) };
            context.rethrow();
            for (lane, hit) in hits.iter_mut().enumerate() {
                if valid.0[lane] != 0 && packet.hit.geomID[lane] != INVALID_ID {
                    *hit = Some(self.hit(
                        packet.ray.tfar[lane] + embree_view(&rays[lane]).1,
                        packet.hit.primID[lane],
                        packet.hit.u[lane],
                        packet.hit.v[lane],
                    ));
                }
            }
        }
    }

    /// Any-hit answers of `rays` in packets of 16, with `filter` (or none) in the context.
    fn any_batch(&self, rays: &[Ray], occluded: &mut [bool], filter: Option<&dyn Fn(u32, f32, f32) -> bool>) {
        assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
        let mut context = FilterContext::new(sys::RTCIntersectContextFlags::COHERENT, filter, &self.ids);
        for (rays, answers) in rays.chunks(PACKET).zip(occluded.chunks_mut(PACKET)) {
            let valid = ValidMask::of(rays);
            answers.fill(false);
            if !valid.any() {
                continue;
            }
            let mut packet = packet_rays(rays);
            let context_pointer: *mut FilterContext = &mut context;
            // SAFETY: as in `closest_batch`; Embree sets `tfar` to -∞ in
            // the lanes whose ray is occluded.
            unsafe { sys::rtcOccluded16(valid.0.as_ptr(), self.scene, context_pointer.cast(), &mut packet) };
            context.rethrow();
            for (lane, answer) in answers.iter_mut().enumerate() {
                *answer = valid.0[lane] != 0 && packet.tfar[lane] == f32::NEG_INFINITY;
            }
        }
    }
}

/// Embree's ray for ours: the same origin, direction (not normalised: `t`
/// is in units of its length, as ours) and segment `[t_min, t_max]`.
fn embree_ray(ray: &Ray) -> sys::RTCRay {
    sys::RTCRay {
        org_x: ray.origin.x,
        org_y: ray.origin.y,
        org_z: ray.origin.z,
        tnear: ray.t_min,
        dir_x: ray.direction.x,
        dir_y: ray.direction.y,
        dir_z: ray.direction.z,
        time: 0.0,
        tfar: ray.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

fn no_hit() -> sys::RTCHit {
    sys::RTCHit {
        Ng_x: 0.0,
        Ng_y: 0.0,
        Ng_z: 0.0,
        u: 0.0,
        v: 0.0,
        primID: INVALID_ID,
        geomID: INVALID_ID,
        instID: [INVALID_ID],
    }
}

/// Embree's intersection context, extended with what the filter callback
/// needs; Embree passes the callback a pointer to `base`, the first field.
#[repr(C)]
struct FilterContext<'a> {
    base: sys::RTCIntersectContext,
    accept: Option<&'a dyn Fn(u32, f32, f32) -> bool>,
    ids: &'a [u32],
    /// A panic of the filter, caught so that it does not unwind through
    /// Embree's C frames, and resumed once the query has returned.
    panic: Option<Box<dyn Any + Send>>,
}

impl<'a> FilterContext<'a> {
    fn new(
        flags: sys::RTCIntersectContextFlags,
        accept: Option<&'a dyn Fn(u32, f32, f32) -> bool>,
        ids: &'a [u32],
    ) -> Self {
        // The fields `rtcInitIntersectContext` sets, plus the filter.
        let base = sys::RTCIntersectContext {
            flags,
            filter: accept.map(|_| filter_hits as unsafe extern "C" fn(*const sys::RTCFilterFunctionNArguments)),
            instID: [INVALID_ID],
        };
        Self { base, accept, ids, panic: None }
    }

    /// Resumes a panic of the filter, if it panicked.
    fn rethrow(&mut self) {
        if let Some(panic) = self.panic.take() {
            resume_unwind(panic);
        }
    }
}

/// Embree's filter callback: rejects (`valid[i] = 0`) the candidate hits
/// that the context's filter does not accept, so that traversal goes on
/// past them, as through an alpha-masked hole.
unsafe extern "C" fn filter_hits(args: *const sys::RTCFilterFunctionNArguments) {
    // SAFETY: Embree calls this with valid arguments for the duration of
    // the call: `context` is the pointer the query was given, which points
    // to the first field of a live `FilterContext` (`closest`, `any` and
    // their batches), so
    // it may be cast back; nothing else accesses that context while the
    // query runs. `valid` holds `N` ints and `hit` is a structure of
    // arrays of `N` lanes per field, laid out as `RTCHitN` documents:
    // Ng_x, Ng_y, Ng_z, u, v, primID, geomID, instID.
    unsafe {
        let args = &*args;
        let context = &mut *args.context.cast::<FilterContext>();
        let Some(accept) = context.accept else { return };
        let lanes = args.N as usize;
        let floats = args.hit.cast::<f32>();
        let words = args.hit.cast::<u32>();
        for lane in 0..lanes {
            let valid = args.valid.add(lane);
            if *valid == 0 {
                continue;
            }
            let (u, v, prim_id) =
                (*floats.add(3 * lanes + lane), *floats.add(4 * lanes + lane), *words.add(5 * lanes + lane));
            let accepted = context.panic.is_none()
                && match catch_unwind(AssertUnwindSafe(|| accept(context.ids[prim_id as usize], u, v))) {
                    Ok(accepted) => accepted,
                    Err(panic) => {
                        context.panic = Some(panic);
                        false
                    }
                };
            if !accepted {
                *valid = 0;
            }
        }
    }
}

/// The valid mask of a packet: -1 for rays to trace, 0 for the others;
/// Embree reads it with aligned 16-wide loads.
#[repr(C, align(64))]
struct ValidMask([c_int; PACKET]);

impl ValidMask {
    fn of(rays: &[Ray]) -> Self {
        let mut mask = [0; PACKET];
        for (lane, ray) in mask.iter_mut().zip(rays) {
            *lane = if traceable(&embree_view(ray).0) { -1 } else { 0 };
        }
        Self(mask)
    }

    fn any(&self) -> bool {
        self.0.iter().any(|&lane| lane != 0)
    }
}

/// A packet of up to 16 rays, in Embree's structure-of-arrays layout;
/// lanes beyond `rays` and lanes of invalid rays are masked off.
fn packet_rays(rays: &[Ray]) -> sys::RTCRay16 {
    let mut packet = sys::RTCRay16 {
        org_x: [0.0; PACKET],
        org_y: [0.0; PACKET],
        org_z: [0.0; PACKET],
        tnear: [0.0; PACKET],
        dir_x: [0.0; PACKET],
        dir_y: [0.0; PACKET],
        dir_z: [1.0; PACKET],
        time: [0.0; PACKET],
        tfar: [0.0; PACKET],
        mask: [u32::MAX; PACKET],
        id: [0; PACKET],
        flags: [0; PACKET],
    };
    for (lane, (ray, _)) in rays.iter().map(embree_view).enumerate().filter(|(_, (r, _))| traceable(r)) {
        packet.org_x[lane] = ray.origin.x;
        packet.org_y[lane] = ray.origin.y;
        packet.org_z[lane] = ray.origin.z;
        packet.tnear[lane] = ray.t_min;
        packet.dir_x[lane] = ray.direction.x;
        packet.dir_y[lane] = ray.direction.y;
        packet.dir_z[lane] = ray.direction.z;
        packet.tfar[lane] = ray.t_max;
        packet.id[lane] = lane as u32;
    }
    packet
}

impl Accel for EmbreeBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.closest(ray, None)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.any(ray, None)
    }

    /// Counts the ray; Embree reports no nodes or triangle tests, so those
    /// counters are left as they are.
    fn intersect_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> Option<Hit> {
        counters.rays += 1;
        self.closest(ray, None)
    }

    /// Counts the ray only, as [`EmbreeBackend::intersect_counted`].
    fn occluded_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> bool {
        counters.rays += 1;
        self.any(ray, None)
    }

    fn intersect_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        self.closest(ray, Some(accept))
    }

    fn occluded_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> bool {
        self.any(ray, Some(accept))
    }

    fn build_stats(&self) -> &BuildStats {
        &self.stats
    }

    /// Packets of 16 rays through `rtcIntersect16`, with the coherent-ray
    /// hint; agrees with [`Accel::intersect`] to rounding (see the type's
    /// documentation).
    fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.closest_batch(rays, hits, None);
    }

    /// Packets of 16 rays through `rtcOccluded16`, with the coherent-ray hint.
    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        self.any_batch(rays, occluded, None);
    }

    /// [`EmbreeBackend::intersect_batch`] with the filter in the context,
    /// called by Embree for the candidate hits of all sixteen lanes.
    fn intersect_batch_filtered(&self, rays: &[Ray], hits: &mut [Option<Hit>], accept: &dyn Fn(u32, f32, f32) -> bool) {
        self.closest_batch(rays, hits, Some(accept));
    }

    /// [`EmbreeBackend::occluded_batch`] with the filter in the context.
    fn occluded_batch_filtered(&self, rays: &[Ray], occluded: &mut [bool], accept: &dyn Fn(u32, f32, f32) -> bool) {
        self.any_batch(rays, occluded, Some(accept));
    }
}
