//! A minimal FFI to Embree 3 (Debian's `libembree-dev`), only for measuring xylem's tracer
//! against it side by side (`xylem bench trace` built with `--features embree-anchor`).
//! Declarations follow embree3/rtcore_*.h (Embree 3.13, RTC_MAX_INSTANCE_LEVEL_COUNT = 1,
//! RTC_MIN_WIDTH = 0).

use std::ffi::c_void;
use std::time::{Duration, Instant};
use xylem::render::geometry::{Ray, TriMesh};

type RtcDevice = *mut c_void;
type RtcScene = *mut c_void;
type RtcGeometry = *mut c_void;

const GEOMETRY_TYPE_TRIANGLE: u32 = 0;
const BUFFER_TYPE_INDEX: u32 = 0;
const BUFFER_TYPE_VERTEX: u32 = 1;
const FORMAT_UINT3: u32 = 0x5003;
const FORMAT_FLOAT3: u32 = 0x9003;
const BUILD_QUALITY_HIGH: u32 = 2;
const INVALID_ID: u32 = u32::MAX;

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

#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

#[repr(C)]
struct RtcIntersectContext {
    flags: u32,
    filter: *const c_void,
    inst_id: [u32; 1],
}

#[link(name = "embree3")]
extern "C" {
    fn rtcNewDevice(config: *const std::ffi::c_char) -> RtcDevice;
    fn rtcReleaseDevice(device: RtcDevice);
    fn rtcNewScene(device: RtcDevice) -> RtcScene;
    fn rtcSetSceneBuildQuality(scene: RtcScene, quality: u32);
    fn rtcCommitScene(scene: RtcScene);
    fn rtcReleaseScene(scene: RtcScene);
    fn rtcNewGeometry(device: RtcDevice, kind: u32) -> RtcGeometry;
    fn rtcSetNewGeometryBuffer(
        geometry: RtcGeometry,
        kind: u32,
        slot: u32,
        format: u32,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    fn rtcCommitGeometry(geometry: RtcGeometry);
    fn rtcAttachGeometry(scene: RtcScene, geometry: RtcGeometry) -> u32;
    fn rtcReleaseGeometry(geometry: RtcGeometry);
    fn rtcIntersect1(scene: RtcScene, context: *mut RtcIntersectContext, rayhit: *mut RtcRayHit);
    fn rtcOccluded1(scene: RtcScene, context: *mut RtcIntersectContext, ray: *mut RtcRay);
}

/// One Embree scene holding one triangle mesh.
pub struct EmbreeScene {
    device: RtcDevice,
    scene: RtcScene,
    /// Wall time from the new scene to its committed BVH (copying the mesh into Embree's buffers
    /// included).
    pub build_time: Duration,
}

fn context(coherent: bool) -> RtcIntersectContext {
    // rtcInitIntersectContext (an inline function in rtcore_common.h).
    RtcIntersectContext {
        flags: coherent as u32,
        filter: std::ptr::null(),
        inst_id: [INVALID_ID],
    }
}

fn rtc_ray(r: &Ray, t_max: f32) -> RtcRay {
    RtcRay {
        org: r.o.to_array(),
        tnear: 0.0,
        dir: r.d.to_array(),
        time: 0.0,
        tfar: t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

impl EmbreeScene {
    /// Builds a high-quality BVH of `mesh` (object space is world space here).
    pub fn new(mesh: &TriMesh) -> Option<EmbreeScene> {
        // SAFETY: plain C calls on handles this function creates; buffers are written within
        // the item counts Embree allocated them with.
        unsafe {
            let device = rtcNewDevice(std::ptr::null());
            if device.is_null() {
                return None;
            }
            let t = Instant::now();
            let scene = rtcNewScene(device);
            rtcSetSceneBuildQuality(scene, BUILD_QUALITY_HIGH);
            let geom = rtcNewGeometry(device, GEOMETRY_TYPE_TRIANGLE);
            let nv = mesh.positions.len();
            let v = rtcSetNewGeometryBuffer(geom, BUFFER_TYPE_VERTEX, 0, FORMAT_FLOAT3, 12, nv)
                as *mut f32;
            let ni = mesh.indices.len();
            let ix = rtcSetNewGeometryBuffer(geom, BUFFER_TYPE_INDEX, 0, FORMAT_UINT3, 12, ni)
                as *mut u32;
            if v.is_null() || ix.is_null() {
                rtcReleaseGeometry(geom);
                rtcReleaseScene(scene);
                rtcReleaseDevice(device);
                return None;
            }
            let vs = std::slice::from_raw_parts_mut(v, nv * 3);
            for (i, p) in mesh.positions.iter().enumerate() {
                vs[3 * i..3 * i + 3].copy_from_slice(&p.to_array());
            }
            let is = std::slice::from_raw_parts_mut(ix, ni * 3);
            for (i, t) in mesh.indices.iter().enumerate() {
                is[3 * i..3 * i + 3].copy_from_slice(t);
            }
            rtcCommitGeometry(geom);
            rtcAttachGeometry(scene, geom);
            rtcReleaseGeometry(geom);
            rtcCommitScene(scene);
            Some(EmbreeScene {
                device,
                scene,
                build_time: t.elapsed(),
            })
        }
    }

    /// Closest-hit distance.
    pub fn intersect(&self, r: &Ray, coherent: bool) -> Option<f32> {
        let mut ctx = context(coherent);
        let mut rh = RtcRayHit {
            ray: rtc_ray(r, f32::INFINITY),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: INVALID_ID,
                geom_id: INVALID_ID,
                inst_id: [INVALID_ID],
            },
        };
        // SAFETY: `self.scene` is a committed scene; the structs match rtcore_ray.h's layout.
        unsafe { rtcIntersect1(self.scene, &mut ctx, &mut rh) };
        (rh.hit.geom_id != INVALID_ID).then_some(rh.ray.tfar)
    }

    /// True when nothing is hit before `t_max`.
    pub fn unoccluded(&self, r: &Ray, t_max: f32, coherent: bool) -> bool {
        let mut ctx = context(coherent);
        let mut ray = rtc_ray(r, t_max);
        // SAFETY: as in `intersect`; Embree sets tfar to −∞ when the ray is occluded.
        unsafe { rtcOccluded1(self.scene, &mut ctx, &mut ray) };
        ray.tfar != f32::NEG_INFINITY
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: releases the handles created in `new`, once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

/// Times Embree on the same rays as [`super::trace::time_rays`].
pub fn time_rays(scene: &EmbreeScene, rays: &[Ray], coherent: bool) -> super::trace::TraceFigures {
    let t0 = super::clock::CpuTimer::thread();
    let hits = rays
        .iter()
        .filter(|r| scene.intersect(r, coherent).is_some())
        .count();
    let closest = t0.elapsed();
    let t1 = super::clock::CpuTimer::thread();
    let free = rays
        .iter()
        .filter(|r| scene.unoccluded(r, f32::INFINITY, coherent))
        .count();
    let any = t1.elapsed();
    debug_assert_eq!(free + hits, rays.len());
    super::trace::figures(rays.len(), hits, closest, any)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::trace::{bumpy_sphere, coherent_rays, incoherent_rays};
    use std::sync::Arc;
    use xylem::render::{Accel, Instance, Transform};

    #[test]
    fn embree_and_obvhs_agree_on_hits() {
        let mesh = bumpy_sphere(20_000);
        let e = EmbreeScene::new(&mesh).unwrap();
        let a = Accel::new(vec![Instance {
            mesh: Arc::new(mesh),
            transform: Transform::identity(),
            material: 0,
            placement: Default::default(),
        }]);
        let mut rays = coherent_rays(2000);
        rays.extend(incoherent_rays(2000, 4));
        for r in &rays {
            let (x, y) = (
                a.intersect(r, f32::INFINITY).map(|h| h.t),
                e.intersect(r, false),
            );
            match (x, y) {
                (None, None) => {}
                (Some(p), Some(q)) => assert!((p - q).abs() < 1e-3 * q.max(1.0), "{p} {q}"),
                other => panic!("{other:?} for {r:?}"),
            }
            assert_eq!(
                a.unoccluded(r, f32::INFINITY),
                e.unoccluded(r, f32::INFINITY, false)
            );
        }
    }
}
