//! Embree 3 (Debian's `libembree-dev`) over the same scene, through the few functions of its C
//! API that a build, closest hits and occlusion need: spheres as Embree's point spheres,
//! triangles as one triangle mesh. Its own intersection arithmetic answers, so distances agree
//! with ours to rounding only.

use host_std::trace::bvh::{Bvh, Primitive};
use sampler_core::glam::Vec3;
use std::ffi::c_void;
use std::ptr;

type Device = *mut c_void;
type RtcScene = *mut c_void;
type Geometry = *mut c_void;

const GEOMETRY_TRIANGLE: u32 = 0;
const GEOMETRY_SPHERE_POINT: u32 = 50;
const BUFFER_INDEX: u32 = 0;
const BUFFER_VERTEX: u32 = 1;
const FORMAT_UINT3: u32 = 0x5003;
const FORMAT_FLOAT3: u32 = 0x9003;
const FORMAT_FLOAT4: u32 = 0x9004;
const BUILD_QUALITY_HIGH: u32 = 2;
const INVALID_ID: u32 = u32::MAX;

/// `RTCIntersectContext` for this build of Embree (one instance level, no minimum width).
#[repr(C)]
struct Context {
    flags: u32,
    filter: *const c_void,
    inst_id: [u32; 1],
}

/// `RTCRay`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `RTCHit`.
#[repr(C, align(16))]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

/// `RTCRayHit`.
#[repr(C)]
struct RayHit {
    ray: RtcRay,
    hit: RtcHit,
}

#[link(name = "embree3")]
unsafe extern "C" {
    fn rtcNewDevice(config: *const i8) -> Device;
    fn rtcReleaseDevice(device: Device);
    fn rtcNewScene(device: Device) -> RtcScene;
    fn rtcReleaseScene(scene: RtcScene);
    fn rtcSetSceneBuildQuality(scene: RtcScene, quality: u32);
    fn rtcNewGeometry(device: Device, kind: u32) -> Geometry;
    fn rtcSetNewGeometryBuffer(g: Geometry, kind: u32, slot: u32, format: u32, stride: usize, n: usize) -> *mut c_void;
    fn rtcCommitGeometry(g: Geometry);
    fn rtcAttachGeometry(scene: RtcScene, g: Geometry) -> u32;
    fn rtcReleaseGeometry(g: Geometry);
    fn rtcCommitScene(scene: RtcScene);
    fn rtcIntersect1(scene: RtcScene, context: *mut Context, rayhit: *mut RayHit);
    fn rtcOccluded1(scene: RtcScene, context: *mut Context, ray: *mut RtcRay);
}

/// An Embree device and the scene committed on it.
pub struct Embree {
    device: Device,
    scene: RtcScene,
}

impl Embree {
    /// Builds over `ours`'s primitives at Embree's high build quality.
    pub fn build(ours: &Bvh) -> Embree {
        let mut spheres = Vec::new();
        let mut vertices = Vec::new();
        for p in ours.primitives() {
            match *p {
                Primitive::Sphere { center, radius, .. } => spheres.push([center.x, center.y, center.z, radius]),
                Primitive::Triangle { v0, e1, e2, .. } => vertices.extend([v0, v0 + e1, v0 + e2].map(|v| v.to_array())),
            }
        }
        // SAFETY: the buffers are allocated by Embree with the sizes written below, and the
        // handles are released in `drop`.
        unsafe {
            let device = rtcNewDevice(c"threads=1".as_ptr());
            assert!(!device.is_null(), "rtcNewDevice failed");
            let scene = rtcNewScene(device);
            rtcSetSceneBuildQuality(scene, BUILD_QUALITY_HIGH);
            if !spheres.is_empty() {
                let g = rtcNewGeometry(device, GEOMETRY_SPHERE_POINT);
                let buf = rtcSetNewGeometryBuffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT4, 16, spheres.len());
                ptr::copy_nonoverlapping(spheres.as_ptr(), buf.cast(), spheres.len());
                attach(scene, g);
            }
            if !vertices.is_empty() {
                let g = rtcNewGeometry(device, GEOMETRY_TRIANGLE);
                let buf = rtcSetNewGeometryBuffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 12, vertices.len());
                ptr::copy_nonoverlapping(vertices.as_ptr(), buf.cast(), vertices.len());
                let n = vertices.len() / 3;
                let idx = rtcSetNewGeometryBuffer(g, BUFFER_INDEX, 0, FORMAT_UINT3, 12, n).cast::<[u32; 3]>();
                for k in 0..n {
                    let i = 3 * k as u32;
                    idx.add(k).write([i, i + 1, i + 2]);
                }
                attach(scene, g);
            }
            rtcCommitScene(scene);
            Embree { device, scene }
        }
    }

    /// The distance to the nearest hit in (t_min, ∞), if any.
    pub fn closest(&self, o: Vec3, d: Vec3, t_min: f32) -> Option<f32> {
        let mut rh = RayHit {
            ray: ray(o, d, t_min),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: INVALID_ID,
                geom_id: INVALID_ID,
                inst_id: [INVALID_ID],
            },
        };
        // SAFETY: the scene is committed; the context and ray are valid for the call.
        unsafe { rtcIntersect1(self.scene, &mut context(), &mut rh) };
        (rh.hit.geom_id != INVALID_ID).then_some(rh.ray.tfar)
    }

    /// Whether anything blocks the ray in (t_min, ∞): Embree sets tfar to −∞ then.
    pub fn occluded(&self, o: Vec3, d: Vec3, t_min: f32) -> bool {
        let mut r = ray(o, d, t_min);
        // SAFETY: as in `closest`.
        unsafe { rtcOccluded1(self.scene, &mut context(), &mut r) };
        r.tfar < 0.0
    }
}

impl Drop for Embree {
    fn drop(&mut self) {
        // SAFETY: both handles were made in `build` and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

/// Commits `g`, attaches it and drops our reference (the scene keeps its own).
unsafe fn attach(scene: RtcScene, g: Geometry) {
    // SAFETY: the caller passes live handles.
    unsafe {
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
    }
}

/// What `rtcInitIntersectContext` (an inline function in the header) sets.
fn context() -> Context {
    Context { flags: 0, filter: ptr::null(), inst_id: [INVALID_ID] }
}

fn ray(o: Vec3, d: Vec3, t_min: f32) -> RtcRay {
    RtcRay {
        org: o.to_array(),
        tnear: t_min,
        dir: d.to_array(),
        time: 0.0,
        tfar: f32::INFINITY,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}
