//! The built scene: shapes with their BVH, BSDFs, emitters, media, the sensor and the integrator
//! (built with its tables); ray queries and emitter sampling (Mitsuba's `Scene`).

use crate::bsdf::Bsdf;
use crate::color::Spectrum;
use crate::emitter::{area, Emitter};
use crate::integrator::desc::Integrator;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::{Aabb, Ray, RayA, Vec2, Vec3};
use crate::medium::Homogeneous;
use crate::sensor::film::Film;
use crate::sensor::sampler_desc::SamplerDesc;
use crate::sensor::Camera;
use crate::shape::accel::Accel;
use crate::shape::{Geometry, Shape};
use crate::texture::Texture;

/// An emitter of the scene: an area light bound to a shape, or a standalone emitter.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one per emitter, never per hit: no need to box
pub enum SceneEmitter {
    /// Mitsuba's `area` emitter (`emitter/area.rs`): emits `radiance` from the front side of shape `shape`.
    Area {
        shape: u32,
        radiance: Texture,
    },
    Other(Emitter),
}

pub struct Scene {
    pub shapes: Vec<Shape>,
    pub accel: Accel,
    pub bsdfs: Vec<Bsdf>,
    pub emitters: Vec<SceneEmitter>,
    /// Index of the environment emitter (envmap or constant), if any.
    pub environment: Option<u32>,
    pub media: Vec<Homogeneous>,
    pub camera: Camera,
    pub film: Film,
    pub sampler: SamplerDesc,
    /// Medium the camera sits in.
    pub sensor_medium: Option<u32>,
    /// The integrator, built with its tables at scene load.
    pub integrator: Integrator,
    pub bounds: Aabb,
    /// Per medium: emitter sampling from inside it always returns 0 (`integrator/enclosure.rs`).
    pub emitters_unreachable: Vec<bool>,
    /// No surface lets a shadow ray through (no null, thindielectric or mask BSDF): shadow-ray
    /// transmittance needs one any-hit query (`integrator/enclosure.rs`).
    pub surfaces_block_shadow_rays: bool,
    /// Every emitter is an area light (`SceneEmitter::Area`, sphere lights included) and there is
    /// at least one: a uniform emitter pick always returns one.
    pub only_area_emitters: bool,
    /// Per emitter: centre and `r²` of a constant sphere light with outward normals, else `None`
    /// (`integrator::volpath::constant_sphere_lights`; what its emitter-skip test reads).
    pub constant_sphere_lights: Vec<Option<(Vec3, f32)>>,
    /// [`Scene::ray_intersect`] runs its AVX2 body ([`ray_avx2_supported`], decided at build: a
    /// field test where it is inlined, instead of the feature cache's test and its cold call).
    pub ray_avx2: bool,
}

/// Whether the CPU runs [`Scene::ray_intersect`]'s AVX2 body.
pub fn ray_avx2_supported() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl Scene {
    /// Closest surface hit: [`Self::ray_intersect_impl`] compiled for AVX2 where the CPU has it
    /// (the same operations in VEX encoding: the same record bit for bit, in fewer instructions,
    /// without the register copies of two-operand SSE), else for the baseline.
    #[inline(always)]
    pub fn ray_intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        #[cfg(target_arch = "x86_64")]
        if self.ray_avx2 {
            // SAFETY: `ray_avx2` is only set where the CPU supports AVX2 (`ray_avx2_supported`).
            return unsafe { self.ray_intersect_avx2(&ray.to_a()) };
        }
        self.ray_intersect_base(&ray.to_a())
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    unsafe fn ray_intersect_avx2(&self, ray: &RayA) -> Option<SurfaceInteraction> {
        self.ray_intersect_impl(ray)
    }

    #[inline(never)]
    fn ray_intersect_base(&self, ray: &RayA) -> Option<SurfaceInteraction> {
        self.ray_intersect_impl(ray)
    }

    #[inline(always)]
    /// (The ray as a [`RayA`]: this body is behind a call that does not inline, see `RayA`.)
    fn ray_intersect_impl(&self, ray_a: &RayA) -> Option<SurfaceInteraction> {
        let hit = self.accel.intersect_a(&self.shapes, ray_a)?;
        // The direction from its vector (not through a `Ray` on the stack, whose narrow stores
        // a wider load could not be forwarded from).
        let d = Vec3::from(ray_a.d);
        // Each arm returns its record whole (built in the return slot, not copied there). The same
        // dispatch as `Shape::interaction`, written out: calling that with the shape set by struct
        // update compiles the volpath loop around it worse (statue σt 2 `volpath`, 4 spp: +0.9 %
        // instructions, callgrind).
        let shape = hit.shape;
        match &self.shapes[shape as usize].geometry {
            Geometry::Mesh(m) => Some(SurfaceInteraction {
                shape,
                ..match self.accel.lane(hit.lane) {
                    Some((lane, v)) => m.interaction_lane(lane, v, hit.b1, hit.b2, hit.t, d),
                    None => m.interaction(hit.prim, hit.b1, hit.b2, hit.t, d),
                }
            }),
            Geometry::Sphere(s) => Some(SurfaceInteraction { shape, ..s.interaction(hit.t, &ray_a.ray()) }),
            Geometry::Disk(disk) => Some(SurfaceInteraction { shape, ..disk.interaction(hit.t, &ray_a.ray()) }),
        }
    }

    /// True when the segment is blocked.
    #[inline]
    pub fn ray_test(&self, ray: &Ray) -> bool {
        self.accel.occluded_inline(&self.shapes, ray)
    }

    /// The BSDF of the shape that was hit.
    #[inline]
    pub fn bsdf(&self, si: &SurfaceInteraction) -> &Bsdf {
        &self.bsdfs[self.shapes[si.shape as usize].bsdf as usize]
    }

    /// Emitter selection probability (uniform, as Mitsuba's `sample_emitter`).
    #[inline]
    pub fn emitter_selection_pdf(&self) -> f32 {
        1.0 / self.emitters.len() as f32
    }

    /// The uniform emitter selection of [`Self::sample_emitter_direction`]: the emitter's index
    /// and the sample with its first coordinate reused for that emitter. `None` without emitters.
    #[inline]
    pub fn select_emitter(&self, sample: Vec2) -> Option<(usize, Vec2)> {
        let n = self.emitters.len();
        if n == 0 {
            return None;
        }
        let x = sample.x * n as f32;
        let index = (x as u32 as usize).min(n - 1);
        Some((index, Vec2::new(x - index as f32, sample.y)))
    }

    /// Pick an emitter uniformly and sample a direction towards it from `ref_p`.
    /// Returns (ds, weight) where weight = L·(geometry)/pdf including the selection probability;
    /// zero weight when the sample failed or (with `test_visibility`) is occluded.
    pub fn sample_emitter_direction(
        &self,
        ref_p: Vec3,
        ref_n: Option<Vec3>,
        sample: Vec2,
        test_visibility: bool,
    ) -> (DirectionSample, Spectrum) {
        self.sample_emitter_direction_inline(ref_p, ref_n, sample, test_visibility)
    }

    /// [`Self::sample_emitter_direction`] inlined into its caller, so the direction sample is
    /// built in place instead of copied through return slots (`path`'s next-event estimation:
    /// -77 instructions per cornell_box sample; the volume integrators keep the call, which their
    /// larger loops prefer).
    #[inline(always)]
    pub fn sample_emitter_direction_inline(
        &self,
        ref_p: Vec3,
        ref_n: Option<Vec3>,
        sample: Vec2,
        test_visibility: bool,
    ) -> (DirectionSample, Spectrum) {
        let Some((index, sample)) = self.select_emitter(sample) else {
            return (DirectionSample::default(), Spectrum::ZERO);
        };
        let n = self.emitters.len();
        let (mut ds, mut weight) = self.sample_one_emitter(index, ref_p, sample);
        ds.emitter = index as u32;
        ds.pdf /= n as f32;
        weight *= n as f32;
        if ds.pdf <= 0.0 || !crate::color::is_finite(weight) {
            return (ds, Spectrum::ZERO);
        }
        if test_visibility && !self.emitter_visible(ref_p, ref_n, &ds) {
            return (ds, Spectrum::ZERO);
        }
        (ds, weight)
    }

    /// True when nothing blocks the segment from `ref_p` to the emitter point of `ds` (for an
    /// infinitely distant emitter: the ray along `ds.d`). With a surface normal `ref_n`, the
    /// origin is offset off the surface to the side of `ds.d`.
    #[inline]
    pub fn emitter_visible(&self, ref_p: Vec3, ref_n: Option<Vec3>, ds: &DirectionSample) -> bool {
        self.emitter_visible_inline(ref_p, ref_n, ds)
    }

    /// [`Self::emitter_visible`] inlined into its caller (`path`'s shadow rays).
    #[inline(always)]
    pub fn emitter_visible_inline(&self, ref_p: Vec3, ref_n: Option<Vec3>, ds: &DirectionSample) -> bool {
        let o = match ref_n {
            Some(nrm) => crate::interaction::offset_origin(ref_p, nrm, ds.d),
            None => ref_p,
        };
        let ray = if ds.dist.is_finite() { crate::interaction::spawn_ray_between(o, ds.p) } else { Ray::new(o, ds.d) };
        !self.ray_test(&ray)
    }

    #[inline(always)]
    fn sample_one_emitter(&self, index: usize, ref_p: Vec3, sample: Vec2) -> (DirectionSample, Spectrum) {
        match &self.emitters[index] {
            SceneEmitter::Other(e) => e.sample_direction(ref_p, sample),
            SceneEmitter::Area { shape, radiance } => {
                area::sample_direction(radiance, &self.shapes[*shape as usize], ref_p, sample)
            }
        }
    }

    /// Solid-angle density (including selection) of sampling `ds` from `ref_p`.
    pub fn pdf_emitter_direction(&self, ref_p: Vec3, ds: &DirectionSample) -> f32 {
        let sel = self.emitter_selection_pdf();
        match &self.emitters[ds.emitter as usize] {
            SceneEmitter::Other(e) => e.pdf_direction(ref_p, ds) * sel,
            SceneEmitter::Area { shape, .. } => area::pdf_direction(&self.shapes[*shape as usize], ref_p, ds) * sel,
        }
    }

    /// Radiance leaving an emitting surface towards the previous vertex (`si.wi`).
    pub fn eval_area_emitter(&self, si: &SurfaceInteraction) -> Spectrum {
        let Some(e) = self.shapes[si.shape as usize].emitter else { return Spectrum::ZERO };
        match &self.emitters[e as usize] {
            SceneEmitter::Area { radiance, .. } => area::eval(radiance, si),
            _ => Spectrum::ZERO,
        }
    }

    /// A direction sample record for an emitter that was hit by a ray from `ref_p` (for MIS pdfs).
    pub fn direction_sample_for_hit(&self, ref_p: Vec3, si: &SurfaceInteraction) -> DirectionSample {
        let d = si.p - ref_p;
        let dist = d.length();
        DirectionSample {
            p: si.p,
            n: si.n,
            uv: si.uv,
            d: d / dist,
            dist,
            pdf: 0.0,
            delta: false,
            emitter: self.shapes[si.shape as usize].emitter.unwrap_or(0),
        }
    }

    /// A direction sample record for the environment seen along `d` (for MIS pdfs).
    pub fn environment_direction_sample(&self, env: u32, d: Vec3) -> DirectionSample {
        DirectionSample { d, dist: f32::INFINITY, emitter: env, ..Default::default() }
    }

    /// Radiance from the environment along an escaping ray direction.
    pub fn eval_environment(&self, d: Vec3) -> Spectrum {
        match self.environment {
            Some(i) => match &self.emitters[i as usize] {
                SceneEmitter::Other(e) => e.eval_environment(d),
                _ => Spectrum::ZERO,
            },
            None => Spectrum::ZERO,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.shapes.iter().map(|s| s.triangle_count()).sum()
    }
}
