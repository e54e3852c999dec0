//! Manifold NEE as one stage of the volpath loop, next to SNEE's (`snee::stage`): its per-path
//! state and the places where the loop asks it something (`volpath_snee`, `connection = complete`
//! only; with `paper` the loop has no such stage). The loop owns the path; this type never edits it.
//!
//! | loop event                   | call                          | what the manifold connection does                |
//! |------------------------------|-------------------------------|--------------------------------------------------|
//! | real scatter `p` in a medium | [`ManifoldStage::at_scatter`] | `x_j = p`; one connection through the flat boundary, MIS-weighted against SNEE run at the previous vertex `x_i` (`manifold::sample`) |
//! | the same scatter             | [`ManifoldStage::chain_at_scatter`], [`ManifoldStage::beams_at_scatter`] | the two-vertex chain (`reflection_chains`); the beams of one light subpath traced at the path's first such vertex (`beam.rs`) |
//! | the ray reaches a surface    | [`ManifoldStage::at_surface`] | takes the pending suffixes `x_j → x_k → …` the ray carries |
//! | an emitter is hit            | [`ManifoldStage::weight`]     | the MIS weight of an escape right after leaving `x_j`'s medium (`manifold::forward_weight`) |
//! | emitter sampling at `x_k`    | [`ManifoldStage::nee_weight`] | the MIS weight of forward NEE at a rough `x_k` right after `x_j` (`rough::nee_weight`) |
//! | BSDF sampling at a surface   | [`ManifoldStage::after_bsdf`] | starts, carries or ends the pending suffixes (`snee::stage::Crossing`) |
//!
//! SNEE's side of the MIS (a SNEE sample the connection could also have made) is one call in
//! `snee/sample.rs` (`manifold::snee_weight`).

use super::beam::{self, BeamSet};
use super::curved_finite;
use super::rough::RoughPending;
use super::track::{Pending, Tracker};
use super::MediumVertex;
use super::{forward_weight, Connection};
use crate::bsdf::BsdfSample;
use crate::color::Spectrum;
use crate::integrator::cx::Cx;
use crate::integrator::cx::Scatter;
use crate::integrator::snee::options::Records;
use crate::integrator::snee::stage::{clear, set, shift, Crossing};
use crate::integrator::snee::{Snee, SneeStage, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::DirectionSample;
use crate::interaction::SurfaceInteraction;
use crate::math::Vec3;
use crate::scene::world::{Scene, SceneEmitter};

/// The records `snee`'s manifold tables (built for `scene`) can start (kept in `Snee::records`).
pub fn records(scene: &Scene, snee: &Snee) -> Records {
    let area_light = scene.emitters.iter().any(|e| matches!(e, SceneEmitter::Area { .. }));
    Records {
        flat: snee.flat.iter().any(Option::is_some),
        rough: snee.rough.iter().any(Option::is_some),
        curved: area_light && snee.curved.iter().any(|&c| c),
    }
}

/// The manifold connection's state along one path.
#[derive(Clone, Debug)]
pub struct ManifoldStage<'a> {
    snee: &'a Snee,
    /// The records kept in this scene (`Snee::records`).
    records: Records,
    /// The last medium vertex `x_j` and the suffix the ray leaving the last surface carries.
    tracker: Tracker,
    /// The pending suffix as it was when the ray reached the current surface (or escaped).
    arrived: Option<Pending>,
    /// The surface the current ray reached (`None`: it escaped, an environment hit).
    hit: Option<SurfaceInteraction>,
    /// The SNEE vertex `x_i` just before the last medium vertex `x_j`, if any.
    x_i: Option<SneeVertex>,
    /// A path that left through a rough plane right after `x_j` (`rough.rs`): as the ray leaving the
    /// last surface carries it, and as it was when the ray reached the current surface.
    rough_pending: Option<RoughPending>,
    rough_arrived: Option<RoughPending>,
    /// A path that left through a curved boundary right after `x_j` (`curved_finite.rs`), likewise.
    curved_pending: Option<curved_finite::Pending>,
    curved_arrived: Option<curved_finite::Pending>,
    /// Did the current ray start at a medium vertex (no surface reached since)?
    after_scatter: bool,
    /// Is the predecessor of the current medium vertex a medium vertex, with no surface between?
    medium_predecessor: bool,
    /// The beams of this path's light subpath (`beam.rs`), traced at its first vertex that needs them.
    beams: Option<BeamSet>,
    /// Has the path had a medium vertex?
    scattered: bool,
    /// Before the first medium vertex: is the path so far a camera prefix that camera beams
    /// connect (`camera_beam.rs`: a delta refraction into a medium's boundary, then delta
    /// reflections on medium boundaries; every BSDF event, a null crossing too, passes
    /// [`Self::after_bsdf`]), and how many reflections has it had?
    prefix_ok: bool,
    prefix_entered: bool,
    prefix_reflections: u32,
    /// Is the current medium vertex the path's first, reached by such a prefix with at most
    /// `camera_reflections` reflections? Camera beams make the chain's paths there.
    camera_first: bool,
}

impl<'a> ManifoldStage<'a> {
    /// The stage for a `volpath_snee` path, `None` unless `connection = complete`.
    pub fn new(scene: &Scene, snee: &'a Snee) -> Option<Self> {
        (scene.integrator.connection == Connection::Complete).then(|| ManifoldStage {
            snee,
            records: snee.records,
            tracker: Tracker::default(),
            arrived: None,
            hit: None,
            x_i: None,
            rough_pending: None,
            rough_arrived: None,
            curved_pending: None,
            curved_arrived: None,
            after_scatter: false,
            medium_predecessor: false,
            beams: None,
            scattered: false,
            prefix_ok: true,
            prefix_entered: false,
            prefix_reflections: 0,
            camera_first: false,
        })
    }

    /// At a real scatter `v` (`x_j = v.p`), after SNEE's stage ran there (its chain gives `x_i`):
    /// one connection. Returns its contribution.
    #[inline]
    pub fn at_scatter(&mut self, cx: &mut Cx, snee: &SneeStage, v: &Scatter) -> Spectrum {
        self.x_i = snee.chain_x_i().copied();
        self.medium_predecessor = std::mem::replace(&mut self.after_scatter, true);
        self.camera_first = !self.scattered
            && self.prefix_ok
            && self.prefix_entered
            && self.prefix_reflections <= self.snee.options.camera_reflections;
        self.scattered = true;
        self.tracker.sample(cx, self.snee.options, snee.chain_x_i(), v)
    }

    /// After [`Self::at_scatter`] at the same vertex: the two-vertex chain (`reflection_chains`,
    /// docs/manifold.md §9), returned apart so that the class tally counts it as internal reflection.
    /// Where beams run, the chain skips vertices whose predecessor is a medium vertex: the beams
    /// connected at that predecessor make those paths (one reflection), so the two partition them;
    /// where camera beams run, it also skips the camera's first medium vertex (`camera_beam.rs`).
    #[inline]
    pub fn chain_at_scatter(&mut self, cx: &mut Cx, v: &Scatter) -> Spectrum {
        if self.medium_predecessor && self.beams_apply(v.medium) {
            return Spectrum::ZERO;
        }
        // Camera beams (`camera_beam.rs`) make the paths from the camera's first medium vertex.
        if self.camera_first && self.snee.camera_beams && self.beams_apply(v.medium) {
            return Spectrum::ZERO;
        }
        super::sample_chain(cx, self.snee.options, v)
    }

    /// Do beams run for a medium vertex in `medium` (`connection = complete`, `beams`, all
    /// transport kept, a directional light and a smooth dielectric boundary: `Snee::beams`)?
    #[inline]
    fn beams_apply(&self, medium: u32) -> bool {
        self.snee.beams.get(medium as usize).is_some_and(Option::is_some)
    }

    /// After [`Self::chain_at_scatter`] at the same vertex `x_a = v.p`: every beam of the path's
    /// light subpath (traced here at the first vertex that needs it) connected to `x_a`
    /// (`beam.rs`), returned apart (class `internal_reflection`). Zero, drawing nothing, where
    /// beams do not apply or the depth budget leaves no room for one reflection.
    #[inline]
    pub fn beams_at_scatter(&mut self, cx: &mut Cx, v: &Scatter) -> Spectrum {
        let Some(Some(b)) = self.snee.beams.get(v.medium as usize) else { return Spectrum::ZERO };
        // x_b, one reflection and the refraction out.
        if v.depth.saturating_add(3) >= v.max_depth {
            return Spectrum::ZERO;
        }
        let set = match &self.beams {
            Some(set) if set.medium == v.medium => set,
            _ => self.beams.insert(beam::trace(cx.scene, v.medium, b, cx.sampler, cx.stats)),
        };
        if set.n == 0 {
            return Spectrum::ZERO;
        }
        beam::connect(cx.scene, set, v, beam::MAX_REFLECTIONS as u32, cx.sampler, cx.stats)
    }

    /// The weight of forward NEE towards `ds` at the current surface, when it is a rough `x_k`
    /// reached right after the medium vertex `x_j` (the manifold connection shares the path);
    /// `None`: the caller's weight stands.
    #[inline]
    pub fn nee_weight(
        &self,
        scene: &Scene,
        ds: &DirectionSample,
        channel: usize,
        stats: &mut LocalStats,
    ) -> Option<f32> {
        let (x_j, si_k) = (self.tracker.x_j.as_ref()?, self.hit.as_ref()?);
        super::rough::nee_weight(scene, self.snee.options, self.x_i.as_ref(), x_j, si_k, ds, channel, stats)
    }

    /// The ray reached a surface (`None`: it escaped).
    #[inline]
    pub fn at_surface(&mut self, si: Option<&SurfaceInteraction>) {
        self.after_scatter = false;
        shift(&mut self.arrived, &mut self.tracker.pending);
        shift(&mut self.rough_arrived, &mut self.rough_pending);
        shift(&mut self.curved_arrived, &mut self.curved_pending);
        // `hit` is read only with a record that arrived or after a medium vertex `x_j` (`weight`,
        // `nee_weight`); otherwise it is not copied and keeps no meaning.
        let read = self.arrived.is_some()
            || self.rough_arrived.is_some()
            || self.curved_arrived.is_some()
            || self.tracker.x_j.is_some();
        if read {
            self.hit = si.copied();
        } else {
            clear(&mut self.hit);
        }
    }

    /// The weight of an emitter hit along `d` by forward tracing, when the manifold connection
    /// shares the path; `None`: the caller's weight stands.
    #[inline]
    pub fn weight(
        &self,
        scene: &Scene,
        snee: &SneeStage,
        d: Vec3,
        channel: usize,
        stats: &mut LocalStats,
    ) -> Option<f32> {
        if let Some(rp) = &self.rough_arrived {
            // Through a rough boundary: an escape to the environment or an area-light hit.
            let hit = self.hit.as_ref();
            return super::rough::emitter_hit_weight(scene, self.snee.options, rp, hit, d, channel, stats);
        }
        if let (Some(cp), Some(y)) = (&self.curved_arrived, &self.hit) {
            return curved_finite::forward_weight(scene, self.snee.options, cp, y, d, channel, stats);
        }
        let opts = Some(self.snee.options);
        forward_weight(scene, opts, self.arrived.as_ref(), snee.arrived(), self.hit.as_ref(), d, channel, stats)
    }

    /// BSDF sampling at `s` chose `bs` towards `wo`: a refraction out right after the medium vertex
    /// `x_j` starts the records of the boundary it left through, a null crossing of a passable
    /// surface carries the records the ray arrived with, anything else ends them. Always ends `x_j`.
    /// (The pending records are empty here: [`Self::at_surface`] moved them to the arrived ones.)
    #[inline]
    pub fn after_bsdf(&mut self, scene: &Scene, s: &SurfaceInteraction, bs: &BsdfSample, wo: Vec3) {
        if !self.scattered && self.prefix_ok {
            self.track_prefix(scene, s, bs);
        }
        debug_assert!(self.rough_pending.is_none() && self.curved_pending.is_none() && self.tracker.pending.is_none());
        let x_j = self.tracker.x_j.take();
        // Nothing to start (no `x_j`) nor to carry: every crossing leaves the records empty.
        if x_j.is_none() && self.arrived.is_none() && self.rough_arrived.is_none() && self.curved_arrived.is_none() {
            return;
        }
        self.records_after_bsdf(scene, s, bs, wo, x_j);
    }

    /// The camera prefix before the first medium vertex (`camera_first`).
    fn track_prefix(&mut self, scene: &Scene, s: &SurfaceInteraction, bs: &BsdfSample) {
        use crate::bsdf::flags;
        let t = bs.sampled_type;
        let boundary = scene.shapes[s.shape as usize].interior.is_some() && t & flags::NULL == 0;
        if !self.prefix_entered {
            self.prefix_entered = true;
            self.prefix_ok = boundary && t & flags::DELTA_TRANSMISSION != 0;
        } else if boundary && t & flags::DELTA_REFLECTION != 0 {
            self.prefix_reflections += 1;
        } else {
            self.prefix_ok = false;
        }
    }

    /// [`Self::after_bsdf`] where `x_j` (taken) or a record that arrived is there.
    fn records_after_bsdf(
        &mut self,
        scene: &Scene,
        s: &SurfaceInteraction,
        bs: &BsdfSample,
        wo: Vec3,
        x_j: Option<MediumVertex>,
    ) {
        let records = self.records;
        match Crossing::of(scene, s, bs, wo) {
            Crossing::Out => {
                let Some(x_j) = x_j else { return self.end_pending() };
                if records.rough {
                    set(&mut self.rough_pending, super::rough::pending(scene, self.x_i, x_j, s));
                }
                if records.curved {
                    set(&mut self.curved_pending, curved_finite::pending(scene, self.x_i, x_j, s));
                }
                if records.flat {
                    set(&mut self.tracker.pending, Pending::start(scene, x_j, s));
                }
            }
            Crossing::Passed => {
                shift(&mut self.rough_pending, &mut self.rough_arrived);
                shift(&mut self.curved_pending, &mut self.curved_arrived);
                shift(&mut self.tracker.pending, &mut self.arrived);
            }
            Crossing::Ends => self.end_pending(),
        }
    }

    /// Empty the pending records (no forward path the connections share goes on).
    #[inline]
    fn end_pending(&mut self) {
        clear(&mut self.rough_pending);
        clear(&mut self.curved_pending);
        clear(&mut self.tracker.pending);
    }
}
