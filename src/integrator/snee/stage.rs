//! SNEE as one stage of the volpath loop (docs/snee.md §3): its per-path state and the five
//! places where the loop asks it something. The loop owns the path; this type never edits it.
//!
//! | loop event                     | call                       | what SNEE does                              |
//! |--------------------------------|----------------------------|---------------------------------------------|
//! | real scatter `p` in a medium   | [`SneeStage::at_scatter`]  | `x_j` of a chain from the last `x_i`; a new `x_i`; one SNEE sample (the technique's `sample`) |
//! | the ray reaches a surface      | [`SneeStage::at_surface`]  | recognises `x_k` after `x_i → x_j`          |
//! | an emitter is hit              | [`SneeStage::weight`]      | the MIS weight of forward BSDF sampling through `x_k` (the technique's `pdf` of that suffix) |
//! | emitter sampling at a surface  | [`SneeStage::weight`]      | the MIS weight of forward NEE at `x_k`      |
//! | BSDF sampling at a surface     | [`SneeStage::after_bsdf`]  | carries the suffix across `x_k` and passable surfaces |

use super::mis::{forward_weight, ForwardTechnique};
use super::options::{Snee, SneeTechnique};
use super::rate::snee_vertex;
use super::{encloses, passable, LightSample, SneeSuffix, SneeVertex};
use crate::bsdf::{flags, BsdfSample};
use crate::color::Spectrum;
use crate::integrator::cx::Cx;
pub use crate::integrator::cx::Scatter;
use crate::integrator::stats::LocalStats;
use crate::integrator::technique::Technique;
use crate::interaction::SurfaceInteraction;
use crate::math::Vec3;
use crate::scene::world::Scene;

/// SNEE's state along one path.
#[derive(Clone, Debug)]
pub struct SneeStage<'a> {
    snee: &'a Snee,
    /// x_i: the last real scatter, when SNEE runs there and no surface event followed.
    x_i: Option<SneeVertex>,
    /// (x_i, x_j): the scatter x_j directly after a SNEE vertex x_i.
    chain: Option<(SneeVertex, Vec3)>,
    /// The suffix x_i → x_j → x_k at the current boundary vertex.
    at_k: Option<SneeSuffix>,
    /// The suffix the ray leaving the last surface carries (after refraction at x_k).
    pending: Option<SneeSuffix>,
    /// `pending` as it was when the ray reached the current surface.
    arrived: Option<SneeSuffix>,
}

impl<'a> SneeStage<'a> {
    pub fn new(snee: &'a Snee) -> Self {
        SneeStage { snee, x_i: None, chain: None, at_k: None, pending: None, arrived: None }
    }

    /// Are contributions outside SNEE's suffixes kept (`transport = all`)?
    #[inline]
    pub fn keeps_all(&self) -> bool {
        self.snee.options.keeps_all()
    }

    /// At a real scatter `v` of the path: the chain `x_i → x_j = v.p` if `x_i` was the last
    /// vertex, `v.p` as the new `x_i`, and one SNEE sample there. Returns its contribution.
    #[inline]
    pub fn at_scatter(&mut self, cx: &mut Cx, v: &Scatter) -> Spectrum {
        self.chain = self.x_i.take().map(|x_i| (x_i, v.p));
        self.x_i = snee_vertex(self.snee, v.medium, v.p, v.wi, v.depth, v.max_depth);
        match &self.x_i {
            Some(x_i) if self.snee.options.technique != SneeTechnique::Forward => {
                self.snee.sample(cx.scene, x_i, v.beta, cx.channel, cx.sampler, cx.stats)
            }
            _ => Spectrum::ZERO,
        }
    }

    /// `x_i` of the chain `x_i → x_j` ending at the current scatter, if `x_i` was a SNEE vertex.
    #[inline]
    pub fn chain_x_i(&self) -> Option<&SneeVertex> {
        self.chain.as_ref().map(|c| &c.0)
    }

    /// The suffix the ray carried when it reached the current surface (after refraction at `x_k`).
    #[inline]
    pub fn arrived(&self) -> Option<&SneeSuffix> {
        self.arrived.as_ref()
    }

    /// The tables SNEE was built with (`volpath_snee`'s).
    #[inline]
    pub fn tables(&self) -> &'a Snee {
        self.snee
    }

    /// The ray along `d` reached a surface (`None`: it escaped). A surface event ends SNEE chains;
    /// it is `x_k` when it follows `x_i → x_j` on a boundary enclosing `x_i`'s medium.
    #[inline]
    pub fn at_surface(&mut self, scene: &Scene, si: Option<&SurfaceInteraction>, d: Vec3) {
        self.x_i = None;
        match (take_some(&mut self.chain), si) {
            (Some((x_i, x_j)), Some(s)) if encloses(scene, s, x_i.medium, d) => {
                self.at_k = Some(SneeSuffix { x_i, x_j, si_k: *s })
            }
            _ => clear(&mut self.at_k),
        }
        shift(&mut self.arrived, &mut self.pending);
    }

    /// The weight of a forward contribution with volpath weight `w_volpath`: an emitter hit by
    /// BSDF sampling ([`ForwardTechnique::Bsdf`], through the suffix the ray carries) or emitter
    /// sampling at the current surface ([`ForwardTechnique::Nee`], through `x_k`).
    #[inline]
    pub fn weight(
        &self,
        scene: &Scene,
        technique: ForwardTechnique,
        light: impl FnOnce() -> LightSample,
        w_volpath: f32,
        channel: usize,
        stats: &mut LocalStats,
    ) -> f32 {
        let suffix = match technique {
            ForwardTechnique::Bsdf => self.arrived.as_ref(),
            ForwardTechnique::Nee => self.at_k.as_ref(),
        };
        let opts = self.snee.options;
        let w = match suffix {
            Some(s) if opts.needs_suffix_pdf() => {
                forward_weight(scene, self.snee, s, &light(), technique, w_volpath, channel, stats)
            }
            _ => None,
        };
        // Outside SNEE's support: volpath's weight (transport = all) or nothing (transport = snee).
        match w {
            Some(w) => w,
            None if opts.keeps_all() => w_volpath,
            None => 0.0,
        }
    }

    /// BSDF sampling at `s` chose `bs` towards `wo`: a refraction out of `x_k` carries its suffix
    /// on, and so does a null crossing of a passable surface (docs/snee.md §1).
    /// (`pending` is empty here: [`Self::at_surface`] moved it to `arrived`.)
    #[inline]
    pub fn after_bsdf(&mut self, scene: &Scene, s: &SurfaceInteraction, bs: &BsdfSample, wo: Vec3) {
        debug_assert!(self.pending.is_none());
        if self.at_k.is_none() && self.arrived.is_none() {
            return;
        }
        match Crossing::of(scene, s, bs, wo) {
            Crossing::Out => set(&mut self.pending, self.at_k),
            Crossing::Passed => set(&mut self.pending, self.arrived),
            Crossing::Ends => {}
        }
    }
}

/// What BSDF sampling at a surface did, as a record of a suffix that the path carries sees it
/// (SNEE's and the manifold connections' pending records; docs/snee.md §1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// A refraction out through the surface (`wo` on the side of its normal): a record may start.
    Out,
    /// A null crossing of a passable surface: the record the ray arrived with goes on.
    Passed,
    /// Anything else: the record ends.
    Ends,
}

impl Crossing {
    /// The crossing at `s` where BSDF sampling chose `bs` towards `wo`.
    #[inline]
    pub fn of(scene: &Scene, s: &SurfaceInteraction, bs: &BsdfSample, wo: Vec3) -> Crossing {
        let non_null = bs.sampled_type & flags::NULL == 0;
        if non_null && bs.sampled_type & flags::TRANSMISSION != 0 && wo.dot(s.n) > 0.0 {
            Crossing::Out
        } else if !non_null && passable(scene, s) {
            Crossing::Passed
        } else {
            Crossing::Ends
        }
    }
}

/// `*arrived = pending.take()`, moving nothing when both are `None`: the stages' pending records
/// (SNEE's suffix, the manifold connections') each hold a whole `SurfaceInteraction` and are mostly
/// `None`.
#[inline(always)]
pub fn shift<T>(arrived: &mut Option<T>, pending: &mut Option<T>) {
    if pending.is_some() || arrived.is_some() {
        *arrived = pending.take();
    }
}

/// `*o = v`, writing nothing when both are `None` (for the same records as [`shift`]).
#[inline(always)]
pub fn set<T>(o: &mut Option<T>, v: Option<T>) {
    if v.is_some() || o.is_some() {
        *o = v;
    }
}

/// `*o = None`, writing nothing when `o` is `None` already (for the same records as [`shift`]).
#[inline(always)]
pub fn clear<T>(o: &mut Option<T>) {
    if o.is_some() {
        *o = None;
    }
}

/// `o.take()` that moves nothing when `o` is `None` (for the same records as [`shift`]).
#[inline(always)]
pub fn take_some<T>(o: &mut Option<T>) -> Option<T> {
    if o.is_some() {
        o.take()
    } else {
        None
    }
}
