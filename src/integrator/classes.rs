//! Transport classes (`snee render --classes`): every contribution of the volpath loop is also
//! added to one of seven channel groups, chosen by the vertex structure of the complete path it
//! belongs to (not by the technique that made it), so the groups sum to the image and MIS-weighted
//! contributions of one path class land in one group. Definitions and decision order:
//! `docs/classes.md`.
//!
//! The loop is generic over a [`Tally`]: [`NoClasses`] (every method empty, so the default render
//! compiles to the loop without classes) or [`Classes`], which follows the path's vertices and
//! classifies each contribution when it is added.

use super::snee::encloses;
use super::snee::light::segment_clear;
use super::stats::LocalStats;
use crate::color::Spectrum;
use crate::interaction::{offset_origin, SurfaceInteraction};
use crate::math::Vec3;
use crate::scene::world::Scene;

/// A transport class (docs/classes.md). The order is the channel order in the EXR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathClass {
    /// No medium vertex on the path.
    Surface,
    /// Exactly one medium vertex, then the light directly or through one transmission: S–V–S_t–L, V–L.
    Single,
    /// V–V–S_t–L with `x_k` in SNEE's support as seen from `x_i` (visible, on the enclosing boundary).
    SneeSupport,
    /// V–V–S_t–L outside it (`x_k` hidden from `x_i`).
    SneeHidden,
    /// ≥ 2 medium vertices, a surface event right before the last one, then S_t–L.
    SurfaceBeforeLast,
    /// Two or more surface events after the last medium vertex, the last a transmission, then L.
    InternalReflection,
    /// Everything else.
    Other,
}

/// Number of classes.
pub const N_CLASSES: usize = 7;

impl PathClass {
    pub const ALL: [PathClass; N_CLASSES] = [
        PathClass::Surface,
        PathClass::Single,
        PathClass::SneeSupport,
        PathClass::SneeHidden,
        PathClass::SurfaceBeforeLast,
        PathClass::InternalReflection,
        PathClass::Other,
    ];

    /// The channel group's name (`<name>.R` …); scripts read these.
    pub fn name(self) -> &'static str {
        match self {
            PathClass::Surface => "surface",
            PathClass::Single => "single",
            PathClass::SneeSupport => "snee_support",
            PathClass::SneeHidden => "snee_hidden",
            PathClass::SurfaceBeforeLast => "surface_before_last",
            PathClass::InternalReflection => "internal_reflection",
            PathClass::Other => "other",
        }
    }
}

/// The radiance of one camera sample split by class.
pub type ClassValues = [Spectrum; N_CLASSES];

/// How a contribution closes the path, relative to the vertices the tally has seen.
#[derive(Clone, Copy, Debug)]
pub enum End<'a> {
    /// Emitter sampling from the current medium vertex: V–L.
    MediumNee,
    /// A SNEE sample at the current medium vertex `x_i`: V–V–S_t–L in SNEE's support.
    Snee,
    /// The manifold connection from the current medium vertex `x_j`: V–S_t–L.
    Manifold,
    /// The two-vertex chain from the current medium vertex (reflection, refraction): V–S_r–S_t–L.
    Chain,
    /// A beam connection from the current medium vertex `x_a` (`manifold/beam.rs`):
    /// V–V–S_r–…–S_r–S_t–L, one or more reflections inside before the exit refraction.
    Beam,
    /// An emitter hit by the path's ray (after the surface events seen so far).
    Hit,
    /// Emitter sampling at the surface `s` the ray along `d` reached, towards `light_d`.
    SurfaceNee { s: &'a SurfaceInteraction, d: Vec3, light_d: Vec3 },
}

/// What the volpath loop tells a class tally (one per camera sample).
pub trait Tally {
    /// A real scatter at `p` in `medium`.
    fn medium_vertex(&mut self, p: Vec3, medium: u32);
    /// A non-null BSDF event at `s`, reached along `d` (`transmission`: the sampled lobe).
    fn surface_vertex(&mut self, s: &SurfaceInteraction, d: Vec3, transmission: bool);
    /// The loop added `c` to the image, closing the path as `end`.
    fn add(&mut self, scene: &Scene, c: Spectrum, end: End);
}

/// No classes: the default render.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoClasses;

impl Tally for NoClasses {
    #[inline(always)]
    fn medium_vertex(&mut self, _: Vec3, _: u32) {}
    #[inline(always)]
    fn surface_vertex(&mut self, _: &SurfaceInteraction, _: Vec3, _: bool) {}
    #[inline(always)]
    fn add(&mut self, _: &Scene, _: Spectrum, _: End) {}
}

/// A vertex before the last medium vertex.
#[derive(Clone, Copy, Debug)]
enum Vertex {
    Camera,
    Surface,
    Medium { p: Vec3, medium: u32 },
}

/// The boundary vertex `x_k`: the first surface event after the last medium vertex.
#[derive(Clone, Copy, Debug)]
struct BoundaryVertex {
    si: SurfaceInteraction,
    /// The direction the ray reached it along.
    d: Vec3,
    /// SNEE's support predicate from `x_i`, once evaluated.
    support: Option<bool>,
}

/// The class tally of one camera sample: the per-class sums and what the classification needs
/// of the path so far.
#[derive(Clone, Debug)]
pub struct Classes {
    pub values: ClassValues,
    /// Medium vertices so far.
    n_medium: u32,
    /// The most recent vertex.
    last: Vertex,
    /// The last medium vertex `x_j` and the vertex before it.
    x_j: Vertex,
    before_x_j: Vertex,
    /// Non-null surface events since `x_j`, and whether the last one was a transmission.
    after: u32,
    last_transmission: bool,
    x_k: Option<BoundaryVertex>,
}

impl Default for Classes {
    fn default() -> Self {
        Classes {
            values: [Spectrum::ZERO; N_CLASSES],
            n_medium: 0,
            last: Vertex::Camera,
            x_j: Vertex::Camera,
            before_x_j: Vertex::Camera,
            after: 0,
            last_transmission: false,
            x_k: None,
        }
    }
}

/// SNEE's support predicate for the chain `x_i → x_j → x_k` (the geometric part of
/// `snee::forward_weight`'s): both medium vertices in the same medium, `x_k` on a boundary
/// enclosing it reached from inside along `d`, and `x_k` visible from `x_i`.
fn in_snee_support(scene: &Scene, x_i: Vertex, x_j: Vertex, x_k: &SurfaceInteraction, d: Vec3) -> bool {
    let (Vertex::Medium { p: p_i, medium: m_i }, Vertex::Medium { medium: m_j, .. }) = (x_i, x_j) else {
        return false;
    };
    if m_i != m_j || !encloses(scene, x_k, m_i, d) {
        return false;
    }
    let inner_k = offset_origin(x_k.p, x_k.n, p_i - x_k.p);
    // Not the render's rays: the tally's own.
    segment_clear(scene, p_i, inner_k, &mut LocalStats::default())
}

impl Classes {
    /// The class of a path whose last medium vertex is followed by `after` surface events, the
    /// last a transmission when `transmission`, then the light; `x_k` is the first of them.
    fn classify(&self, scene: &Scene, after: u32, transmission: bool, x_k: Option<&mut BoundaryVertex>) -> PathClass {
        if self.n_medium == 0 {
            return PathClass::Surface;
        }
        match after {
            0 if self.n_medium == 1 => PathClass::Single,
            0 => PathClass::Other,
            _ if !transmission => PathClass::Other,
            1 if self.n_medium == 1 => PathClass::Single,
            1 => match (self.before_x_j, x_k) {
                (Vertex::Medium { .. }, Some(k)) => {
                    let support =
                        *k.support.get_or_insert_with(|| in_snee_support(scene, self.before_x_j, self.x_j, &k.si, k.d));
                    if support {
                        PathClass::SneeSupport
                    } else {
                        PathClass::SneeHidden
                    }
                }
                (Vertex::Medium { .. }, None) => PathClass::SneeHidden,
                _ => PathClass::SurfaceBeforeLast,
            },
            _ => PathClass::InternalReflection,
        }
    }
}

impl Tally for Classes {
    #[inline]
    fn medium_vertex(&mut self, p: Vec3, medium: u32) {
        self.n_medium += 1;
        self.before_x_j = self.last;
        self.x_j = Vertex::Medium { p, medium };
        self.last = self.x_j;
        self.after = 0;
        self.last_transmission = false;
        self.x_k = None;
    }

    #[inline]
    fn surface_vertex(&mut self, s: &SurfaceInteraction, d: Vec3, transmission: bool) {
        self.last = Vertex::Surface;
        self.after += 1;
        self.last_transmission = transmission;
        if self.after == 1 {
            self.x_k = Some(BoundaryVertex { si: *s, d, support: None });
        }
    }

    fn add(&mut self, scene: &Scene, c: Spectrum, end: End) {
        let class = match end {
            End::Snee => PathClass::SneeSupport,
            End::MediumNee => self.classify(scene, 0, false, None),
            // x_k of a manifold connection is not known here: a V–V–S_t–L connection counts as
            // in SNEE's support (exact on convex boundaries, docs/classes.md).
            End::Manifold => match (self.n_medium, self.before_x_j) {
                (1, _) => PathClass::Single,
                (_, Vertex::Medium { .. }) => PathClass::SneeSupport,
                _ => PathClass::SurfaceBeforeLast,
            },
            End::Chain | End::Beam => PathClass::InternalReflection,
            End::Hit => {
                let mut x_k = self.x_k.take();
                let class = self.classify(scene, self.after, self.last_transmission, x_k.as_mut());
                self.x_k = x_k;
                class
            }
            End::SurfaceNee { s, d, light_d } => {
                // The NEE event at `s`: a transmission when the light is on the other side.
                let transmission = s.wi.z * s.to_local(light_d).z < 0.0;
                if self.after == 0 {
                    let mut k = BoundaryVertex { si: *s, d, support: None };
                    self.classify(scene, 1, transmission, Some(&mut k))
                } else {
                    let mut x_k = self.x_k.take();
                    let class = self.classify(scene, self.after + 1, transmission, x_k.as_mut());
                    self.x_k = x_k;
                    class
                }
            }
        };
        self.values[class as usize] += c;
    }
}
