//! `volpath_snee`'s options (its XML parameters, parsed in `integrator/volpath_snee.rs`) and the
//! tables built from them once at scene load ([`Snee`]). Plain data: the scene stores it.

/// How SNEE and forward tracing share the suffixes both can produce (`snee` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SneeTechnique {
    Mis,
    Snee,
    Forward,
}

/// Which light transport is rendered (`transport` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SneeTransport {
    All,
    /// Only the suffixes `x_i → x_j → x_k → emitter` in SNEE's support.
    Snee,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SneeOptions {
    pub technique: SneeTechnique,
    pub transport: SneeTransport,
    /// `snee_rate`; `None`: [`auto_rate`] per medium.
    pub rate: Option<f32>,
    /// `reflection_chains` (with `connection = complete`): also the two-vertex chains (internal
    /// reflection, then refraction) of `manifold/chain.rs` under a directional light.
    pub chains: bool,
    /// `connection_rate` (with `connection = complete`): the probability `q` that the curved
    /// area-light connection (`manifold/curved_finite.rs`) runs at a medium vertex whose emitter
    /// sample picked an area light; `None`: `manifold::curved_finite::RATE`.
    pub connection_rate: Option<f32>,
    /// `split_glints` (with `connection = complete`): emitter splitting at smooth dielectric
    /// vertices (`manifold/split.rs`).
    pub split_glints: bool,
    /// `beams` (with `connection = complete`): light-traced internal-reflection segments under a
    /// directional light, connected to camera medium vertices (`manifold/beam.rs`).
    pub beams: bool,
    /// `camera_beams` (with `connection = complete` and `beams`): light-traced beam points
    /// connected to the camera through one refraction (`manifold/camera_beam.rs`).
    pub camera_beams: bool,
    /// `camera_reflections` ∈ {0, 1, 2}: internal reflections of the camera ray before `x_b`
    /// that camera beams connect through (`manifold/camera_beam.rs`).
    pub camera_reflections: u32,
    /// `inner_glints` (with `connection = complete`): the camera's glints also through one
    /// internal reflection (`manifold/glint.rs`, `Chain::Inside`).
    pub inner_glints: bool,
}

impl Default for SneeOptions {
    fn default() -> Self {
        SneeOptions {
            technique: SneeTechnique::Mis,
            transport: SneeTransport::All,
            rate: None,
            chains: false,
            connection_rate: None,
            split_glints: true,
            beams: true,
            camera_beams: false,
            camera_reflections: 0,
            inner_glints: false,
        }
    }
}

impl SneeOptions {
    /// Does forward tracing need SNEE's density of its suffixes (for MIS or for the transport filter)?
    #[inline]
    pub fn needs_suffix_pdf(&self) -> bool {
        self.technique != SneeTechnique::Forward || self.transport == SneeTransport::Snee
    }
    /// Are contributions outside SNEE's suffixes kept?
    #[inline]
    pub fn keeps_all(&self) -> bool {
        self.transport == SneeTransport::All
    }
}

/// `volpath_snee` as built at scene load: its options and the per-medium tables SNEE reads at every
/// vertex (computed once by `snee::rate::build`).
#[derive(Clone, Debug, PartialEq)]
pub struct Snee {
    pub options: SneeOptions,
    /// Per medium: `None` where SNEE does not apply, else the probability `r` that SNEE runs at
    /// one of its scattering vertices (docs/snee.md §5).
    pub rates: Vec<Option<f32>>,
    /// Does the scene have a non-delta emitter (area, envmap, constant, ...)? Decides the mixture
    /// of ↓ and ↑ at a smooth boundary (docs/snee.md §2.5).
    pub has_non_delta_emitter: bool,
    /// Per medium: its flat smooth boundary where the manifold connection applies
    /// (`connection = complete`, `manifold::flat::flat_boundaries`; empty with `paper`).
    pub flat: Vec<Option<crate::integrator::manifold::planes::FlatBoundary>>,
    /// Per medium: its flat rough boundary where the manifold connection applies
    /// (`connection = complete`, `manifold::rough::rough_boundaries`; empty with `paper`).
    pub rough: Vec<Option<crate::integrator::manifold::planes::RoughBoundary>>,
    /// Per medium: does the curved connection apply (`manifold::curved::curved_boundaries`)?
    pub curved: Vec<bool>,
    /// Which pending records the manifold stage keeps in this scene (from the three tables above;
    /// all `false` with `paper`).
    pub records: Records,
    /// Nothing of `volpath_snee` runs in this scene (no SNEE rate above 0, no manifold connection
    /// or glint that serves its emitters, all transport kept): `li` is then volpath's loop, whose
    /// estimate `volpath_snee`'s would equal (`volpath_snee::forward_only`, docs/snee.md §5).
    pub forward_only: bool,
    /// Has the scene a `directional` emitter (the only emitters the camera's glints take,
    /// `manifold::glint`)? Decided at build, so that `li` does not scan the emitters per sample.
    pub has_directional: bool,
    /// With `connection = complete`: the irradiance meter's direction mixture towards the glints
    /// of directional lights on the rough boundary it faces (`manifold::meter_glint`).
    pub meter_glint: Option<crate::integrator::manifold::meter_glint::MeterGlint>,
    /// With `connection = complete` and a `perspective` sensor: its map from film positions to
    /// directions, for the camera's glints and camera beams (built once at load).
    pub camera: Option<crate::integrator::manifold::glint::CameraMap>,
    /// With `connection = complete` and `split_glints`: what emitter splitting at smooth
    /// dielectric vertices needs of the scene (`manifold::split`); `None` where it does not run.
    pub split: Option<crate::integrator::manifold::split_bounds::SplitTables>,
    /// With `connection = complete` and `beams`: per medium, the boundary where beams apply
    /// (`manifold::beam::beam_boundaries`); empty elsewhere.
    pub beams: Vec<Option<crate::integrator::manifold::beam_boundary::BeamBoundary>>,
    /// Do camera beams run (`manifold::camera_beam::applies`, decided at load)?
    pub camera_beams: bool,
}

/// Which estimator `volpath_snee` runs (`connection` parameter).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Connection {
    /// The paper's: SNEE and forward tracing only.
    #[default]
    Paper,
    /// Also the manifold connection at every medium vertex (where it applies), MIS with SNEE.
    Complete,
}

impl Connection {
    pub fn name(self) -> &'static str {
        match self {
            Connection::Paper => "paper",
            Connection::Complete => "complete",
        }
    }
}

/// Which of the stage's pending records can ever start in a scene, decided once at scene load
/// (`manifold::stage::records`, called by `volpath_snee::build`, kept in `Snee::records`): a record no connection of the scene can start
/// is never written, moved or looked up along a path. A record that could start but has no use is
/// left out too: the curved one is read only at an area light's hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Records {
    /// Through a flat plane of a smooth boundary (`manifold::track::Pending`): some medium has a flat
    /// boundary (`Snee::flat`).
    pub flat: bool,
    /// Through a flat or curved rough boundary (`manifold::rough::RoughPending`): some medium has one
    /// (`Snee::rough`).
    pub rough: bool,
    /// Through a curved smooth boundary (`curved_finite::Pending`): some medium has one where the
    /// curved connection applies (`Snee::curved`), and the scene has an area light.
    pub curved: bool,
}
