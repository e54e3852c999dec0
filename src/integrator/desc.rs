//! What the scene stores about its integrator (plain data, no rendering code, so that
//! `scene/world.rs` can hold it without an import circle): the parsed options
//! ([`IntegratorDesc`], Mitsuba's `MonteCarloIntegrator` parameters) and the integrator as built at
//! scene load ([`Integrator`], with its per-scene tables). Rendering is `Integrator::li` in
//! `integrator/mod.rs`; parsing is in the plugin files (`integrator/mod.rs`, `moment.rs`,
//! `volpath_snee.rs`).

use super::snee::options::{Connection, Snee, SneeOptions};
use std::ops::{Deref, DerefMut};

/// The XML integrator type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    Path,
    Volpath,
    Volpathmis,
    VolpathSnee,
}

/// Integrator settings (Mitsuba's `MonteCarloIntegrator` parameters).
#[derive(Clone, Debug)]
pub struct IntegratorDesc {
    pub kind: IntegratorKind,
    /// -1 = unbounded.
    pub max_depth: i32,
    pub rr_depth: i32,
    pub hide_emitters: bool,
    /// Wrapped in `moment`: also output the per-pixel second moment.
    pub moment: bool,
    /// `snee render --classes`: also output the image split by transport class (`classes.rs`).
    pub classes: bool,
    /// `volpath_snee`'s `snee`, `transport` and `snee_rate` options (defaults elsewhere).
    pub snee: SneeOptions,
    /// `volpath_snee`'s `connection`: the paper's estimator or the complete one (manifold NEE).
    pub connection: Connection,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc {
            kind: IntegratorKind::Path,
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            moment: false,
            classes: false,
            snee: SneeOptions::default(),
            connection: Connection::default(),
        }
    }
}

/// The integrator as built at scene load: its settings (reachable as fields through `Deref`) and
/// what it precomputes from the scene.
/// Built once per scene and read in place by every path (no box: that would put one more
/// indirection on each of the loop's table look-ups), so the size difference does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Integrator {
    Path(IntegratorDesc),
    Volpath(IntegratorDesc),
    Volpathmis(IntegratorDesc),
    /// With SNEE's per-medium rates and emitter mixture (`snee::rate::build`), and the manifold
    /// connection's flat boundaries (`manifold::flat::flat_boundaries`).
    VolpathSnee(IntegratorDesc, Snee),
}

impl Deref for Integrator {
    type Target = IntegratorDesc;
    fn deref(&self) -> &IntegratorDesc {
        match self {
            Integrator::Path(d)
            | Integrator::Volpath(d)
            | Integrator::Volpathmis(d)
            | Integrator::VolpathSnee(d, _) => d,
        }
    }
}

impl DerefMut for Integrator {
    fn deref_mut(&mut self) -> &mut IntegratorDesc {
        match self {
            Integrator::Path(d)
            | Integrator::Volpath(d)
            | Integrator::Volpathmis(d)
            | Integrator::VolpathSnee(d, _) => d,
        }
    }
}
