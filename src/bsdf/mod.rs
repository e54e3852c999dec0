//! BSDFs (Mitsuba contract: `eval` includes the cosine, `sample` returns the weight f·cos/pdf).
//!
//! Every BSDF works in the local shading frame: `si.wi` and `wo` point away from the surface and
//! +Z is the shading normal. The contract follows Mitsuba 3.9:
//! - [`Bsdf::eval`] returns f(wi, wo)·|cos θo| (0 for delta lobes);
//! - [`Bsdf::pdf`] is the solid-angle density of [`Bsdf::sample`] (0 for delta lobes);
//! - [`Bsdf::sample`] returns `(BsdfSample, weight)` with weight = f·|cos θo| / pdf (for delta
//!   lobes: the lobe's throughput divided by its selection probability). `None` replaces
//!   Mitsuba's inactive or zero-weight samples;
//! - transmission in [`TransportMode::Radiance`] carries the 1/η² solid-angle compression.
//!
//! Components are numbered like Mitsuba's: `dielectric` 0 = reflection, 1 = transmission;
//! [`BsdfContext::component`] restricts sampling/evaluation to one of them (then it is sampled with
//! probability 1 and the weight carries the Fresnel factor).
//!
//! Supported plugins: `diffuse`, `dielectric`, `thindielectric`, `roughdielectric`, `null`, `twosided`,
//! `conductor`, `roughconductor`, `plastic`, `roughplastic`, `mask`.

pub mod conductor;
pub mod conductor_materials;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod mask;
pub mod microfacet;
pub mod null;
pub mod plastic;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod rough_plastic;
pub mod thin_dielectric;
pub mod twosided;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use mask::Mask;
pub use plastic::Plastic;
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::RoughPlastic;
pub use thin_dielectric::ThinDielectric;

use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{Vec2, Vec3};
use crate::scene::desc::{ObjectDesc, Props};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use crate::texture::Texture;

/// Lobe flags, bit for bit Mitsuba's `BSDFFlags`.
pub mod flags {
    /// No flags.
    pub const EMPTY: u32 = 0;
    /// Null scattering: the ray continues undeflected.
    pub const NULL: u32 = 0x00001;
    pub const DIFFUSE_REFLECTION: u32 = 0x00002;
    pub const DIFFUSE_TRANSMISSION: u32 = 0x00004;
    pub const GLOSSY_REFLECTION: u32 = 0x00008;
    pub const GLOSSY_TRANSMISSION: u32 = 0x00010;
    pub const DELTA_REFLECTION: u32 = 0x00020;
    pub const DELTA_TRANSMISSION: u32 = 0x00040;
    pub const DELTA_1D_REFLECTION: u32 = 0x00080;
    pub const DELTA_1D_TRANSMISSION: u32 = 0x00100;
    pub const ANISOTROPIC: u32 = 0x01000;
    pub const SPATIALLY_VARYING: u32 = 0x02000;
    /// Non-symmetric scattering (e.g. transmission through a dielectric).
    pub const NON_SYMMETRIC: u32 = 0x04000;
    /// Scatters light arriving on the side the normal points to.
    pub const FRONT_SIDE: u32 = 0x08000;
    /// Scatters light arriving on the other side.
    pub const BACK_SIDE: u32 = 0x10000;
    pub const NEEDS_DIFFERENTIALS: u32 = 0x20000;

    pub const REFLECTION: u32 = DIFFUSE_REFLECTION | DELTA_REFLECTION | DELTA_1D_REFLECTION | GLOSSY_REFLECTION;
    pub const TRANSMISSION: u32 =
        DIFFUSE_TRANSMISSION | DELTA_TRANSMISSION | DELTA_1D_TRANSMISSION | GLOSSY_TRANSMISSION | NULL;
    pub const DIFFUSE: u32 = DIFFUSE_REFLECTION | DIFFUSE_TRANSMISSION;
    pub const GLOSSY: u32 = GLOSSY_REFLECTION | GLOSSY_TRANSMISSION;
    /// Scattering into a 2D set of directions.
    pub const SMOOTH: u32 = DIFFUSE | GLOSSY;
    /// Scattering into a discrete set of directions.
    pub const DELTA: u32 = NULL | DELTA_REFLECTION | DELTA_TRANSMISSION;
    pub const DELTA_1D: u32 = DELTA_1D_REFLECTION | DELTA_1D_TRANSMISSION;
    /// Any kind of scattering (0x1FF, the default type mask).
    pub const ALL: u32 = DIFFUSE | GLOSSY | DELTA | DELTA_1D;
}

/// Which quantity is transported along the path (Mitsuba's `TransportMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Paths traced from the camera (radiance): transmission is scaled by 1/η².
    Radiance,
    /// Paths traced from the lights (importance).
    Importance,
}

/// What to sample or evaluate (Mitsuba's `BSDFContext`).
#[derive(Clone, Copy, Debug)]
pub struct BsdfContext {
    pub mode: TransportMode,
    /// Lobe types allowed ([`flags::ALL`] by default).
    pub type_mask: u32,
    /// Component index, `u32::MAX` = all components.
    pub component: u32,
}

impl Default for BsdfContext {
    fn default() -> Self {
        BsdfContext { mode: TransportMode::Radiance, type_mask: flags::ALL, component: u32::MAX }
    }
}

impl BsdfContext {
    /// A context for one transport mode with all lobes enabled.
    pub fn new(mode: TransportMode) -> Self {
        BsdfContext { mode, ..Default::default() }
    }

    /// Is the lobe type `ty` of component `component` enabled? (Mitsuba's `is_enabled`.)
    #[inline]
    pub fn is_enabled(&self, ty: u32, component: u32) -> bool {
        (self.type_mask == u32::MAX || (self.type_mask & ty) == ty)
            && (self.component == u32::MAX || self.component == component)
    }
}

/// A sampled outgoing direction (Mitsuba's `BSDFSample3f`).
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Outgoing direction in the local shading frame.
    pub wo: Vec3,
    /// Density of `wo` (solid angle for smooth lobes; the discrete probability for delta lobes).
    pub pdf: f32,
    /// Relative index of refraction along the sampled direction (1 for reflection and null).
    pub eta: f32,
    /// The lobe type that was sampled (one of the [`flags`] lobe bits).
    pub sampled_type: u32,
    /// The component index that was sampled.
    pub sampled_component: u32,
}

/// A surface scattering model (closed set of Mitsuba plugins).
#[derive(Clone, Debug)]
pub enum Bsdf {
    Diffuse(Diffuse),
    Dielectric(Dielectric),
    ThinDielectric(ThinDielectric),
    RoughDielectric(RoughDielectric),
    Null,
    /// `twosided`: front and back models (the same model twice when one was given).
    TwoSided(Box<Bsdf>, Box<Bsdf>),
    Conductor(Conductor),
    RoughConductor(RoughConductor),
    Plastic(Plastic),
    RoughPlastic(RoughPlastic),
    Mask(Mask),
}

/// The plugin names [`Bsdf::from_desc`] accepts.
pub const SUPPORTED_PLUGINS: &[&str] = &[
    "diffuse",
    "dielectric",
    "thindielectric",
    "roughdielectric",
    "null",
    "twosided",
    "conductor",
    "roughconductor",
    "plastic",
    "roughplastic",
    "mask",
];

impl Bsdf {
    /// From a `<bsdf>` object; unknown plugin → error at its position listing the supported ones; calls `props.finish()`.
    pub fn from_desc(obj: &ObjectDesc, resolver: &FileResolver) -> Result<Bsdf> {
        let props = &obj.props;
        let bsdf = match obj.plugin.as_str() {
            "diffuse" => Bsdf::Diffuse(Diffuse::from_props(props, resolver)?),
            "dielectric" => Bsdf::Dielectric(Dielectric::from_props(props, resolver)?),
            "thindielectric" => Bsdf::ThinDielectric(ThinDielectric::from_props(props, resolver)?),
            "roughdielectric" => Bsdf::RoughDielectric(RoughDielectric::from_props(props, resolver)?),
            "null" => Bsdf::Null,
            "twosided" => twosided::from_props(props, resolver)?,
            "conductor" => Bsdf::Conductor(Conductor::from_props(props, resolver)?),
            "roughconductor" => Bsdf::RoughConductor(RoughConductor::from_props(props, resolver)?),
            "plastic" => Bsdf::Plastic(Plastic::from_props(props, resolver)?),
            "roughplastic" => Bsdf::RoughPlastic(RoughPlastic::from_props(props, resolver)?),
            "mask" => Bsdf::Mask(Mask::from_props(props, resolver)?),
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("unsupported bsdf plugin \"{}\" (supported: {})", other, SUPPORTED_PLUGINS.join(", ")),
                ))
            }
        };
        props.finish()?;
        Ok(bsdf)
    }

    /// Number of components (lobes that can be selected with [`BsdfContext::component`]).
    pub fn component_count(&self) -> u32 {
        match self {
            Bsdf::Diffuse(_) | Bsdf::Null => 1,
            Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::RoughDielectric(_) => 2,
            Bsdf::TwoSided(front, back) => front.component_count() + back.component_count(),
            Bsdf::Conductor(_) | Bsdf::RoughConductor(_) => 1,
            Bsdf::Plastic(_) | Bsdf::RoughPlastic(_) => 2,
            Bsdf::Mask(b) => b.component_count(),
        }
    }

    /// Flags of component `i` (0 when out of range).
    #[inline]
    pub fn component_flags(&self, i: u32) -> u32 {
        match self {
            Bsdf::Diffuse(_) => diffuse::component_flags(i),
            Bsdf::Dielectric(_) => dielectric::component_flags(i),
            Bsdf::ThinDielectric(_) => thin_dielectric::component_flags(i),
            Bsdf::RoughDielectric(b) => b.component_flags(i),
            Bsdf::Null => null::component_flags(i),
            Bsdf::TwoSided(front, back) => twosided::component_flags(front, back, i),
            Bsdf::Conductor(_) => conductor::component_flags(i),
            Bsdf::RoughConductor(b) => b.component_flags(i),
            Bsdf::Plastic(_) => plastic::component_flags(i),
            Bsdf::RoughPlastic(_) => rough_plastic::component_flags(i),
            Bsdf::Mask(b) => b.component_flags(i),
        }
    }

    /// Whether evaluating or sampling this model reads the hit's uv (a spatially varying texture
    /// in it or in a nested model). Decided once at scene build, so that shapes whose uv costs
    /// transcendentals (the sphere's acos / atan2) compute it only when it is read.
    pub fn needs_uv(&self) -> bool {
        let varying = |t: &Texture| t.is_spatially_varying();
        let opt = |t: &Option<Texture>| t.as_ref().is_some_and(varying);
        match self {
            Bsdf::Diffuse(b) => varying(&b.reflectance),
            Bsdf::Dielectric(b) => opt(&b.specular_reflectance) || opt(&b.specular_transmittance),
            Bsdf::ThinDielectric(b) => opt(&b.specular_reflectance) || opt(&b.specular_transmittance),
            Bsdf::RoughDielectric(b) => opt(&b.specular_reflectance) || opt(&b.specular_transmittance),
            Bsdf::Null => false,
            Bsdf::TwoSided(front, back) => front.needs_uv() || back.needs_uv(),
            Bsdf::Conductor(b) => varying(&b.ior.eta) || varying(&b.ior.k) || opt(&b.specular_reflectance),
            Bsdf::RoughConductor(b) => {
                varying(&b.ior.eta)
                    || varying(&b.ior.k)
                    || varying(&b.alpha_u)
                    || varying(&b.alpha_v)
                    || opt(&b.specular_reflectance)
            }
            Bsdf::Plastic(b) => varying(&b.diffuse_reflectance) || opt(&b.specular_reflectance),
            Bsdf::RoughPlastic(b) => varying(&b.diffuse_reflectance) || opt(&b.specular_reflectance),
            Bsdf::Mask(b) => varying(&b.opacity) || b.nested.needs_uv(),
        }
    }

    /// Union of all component flags (Mitsuba's `BSDF::flags()`). Asked at every surface vertex:
    /// the leaf BSDFs have at most two lobes (and flags 0 past their last), so their union is
    /// that of lobes 0 and 1, without the loop: a constant per model (`flags_are_the_union_of_the_lobes`
    /// checks them). The nested models are asked lobe by lobe.
    #[inline]
    pub fn flags(&self) -> u32 {
        match self {
            Bsdf::Diffuse(_) => diffuse::component_flags(0) | diffuse::component_flags(1),
            Bsdf::Dielectric(_) => dielectric::component_flags(0) | dielectric::component_flags(1),
            Bsdf::ThinDielectric(_) => thin_dielectric::component_flags(0) | thin_dielectric::component_flags(1),
            Bsdf::Null => null::component_flags(0) | null::component_flags(1),
            Bsdf::Conductor(_) => conductor::component_flags(0) | conductor::component_flags(1),
            Bsdf::Plastic(_) => plastic::component_flags(0) | plastic::component_flags(1),
            Bsdf::RoughPlastic(_) => rough_plastic::component_flags(0) | rough_plastic::component_flags(1),
            Bsdf::TwoSided(..) | Bsdf::Mask(_) | Bsdf::RoughDielectric(_) | Bsdf::RoughConductor(_) => {
                self.nested_flags()
            }
        }
    }

    /// [`Bsdf::flags`] of the models whose lobes depend on their parameters or children.
    #[inline(never)]
    fn nested_flags(&self) -> u32 {
        (0..self.component_count()).fold(0, |acc, i| acc | self.component_flags(i))
    }

    /// True when some lobe of the given type(s) exists.
    #[inline]
    pub fn has_flag(&self, f: u32) -> bool {
        self.flags() & f != 0
    }

    /// Sample an outgoing direction; weight = f·|cos θo|/pdf (Mitsuba). `None` when nothing is
    /// sampled or the weight is zero.
    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        nonzero(match self {
            Bsdf::Diffuse(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::Dielectric(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::ThinDielectric(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::RoughDielectric(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::Null => null::sample(ctx, si),
            Bsdf::TwoSided(front, back) => twosided::sample(front, back, ctx, si, sample1, sample2),
            Bsdf::Conductor(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::RoughConductor(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::Plastic(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::RoughPlastic(b) => b.sample(ctx, si, sample1, sample2),
            Bsdf::Mask(b) => b.sample(ctx, si, sample1, sample2),
        })
    }

    /// [`Bsdf::sample`] (with `s1`, `s2` its `sample1`, `sample2`) with the `diffuse` model built
    /// into the caller and the other models called (the same results): `path`'s loop, where
    /// surface scenes are mostly diffuse.
    #[inline(always)]
    pub fn sample_inline(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        s1: f32,
        s2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        match self {
            Bsdf::Diffuse(b) => nonzero(b.sample(ctx, si, s1, s2)),
            _ => self.sample(ctx, si, s1, s2),
        }
    }

    /// f(wi, wo)·|cos θo| for `wo` in the local frame.
    pub fn eval(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> Spectrum {
        match self {
            Bsdf::Diffuse(b) => b.eval(ctx, si, wo),
            Bsdf::RoughDielectric(b) => b.eval_pdf(ctx, si, wo).0,
            Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::Null => Spectrum::ZERO,
            Bsdf::TwoSided(front, back) => twosided::eval_pdf(front, back, ctx, si, wo).0,
            Bsdf::Conductor(_) => Spectrum::ZERO,
            Bsdf::RoughConductor(b) => b.eval_pdf(ctx, si, wo).0,
            Bsdf::Plastic(b) => b.eval_pdf(ctx, si, wo).0,
            Bsdf::RoughPlastic(b) => b.eval_pdf(ctx, si, wo).0,
            Bsdf::Mask(b) => b.eval_pdf(ctx, si, wo).0,
        }
    }

    /// Solid-angle density with which [`sample`](Self::sample) produces `wo`.
    pub fn pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> f32 {
        match self {
            Bsdf::Diffuse(b) => b.pdf(ctx, si, wo),
            Bsdf::RoughDielectric(b) => b.pdf(ctx, si, wo),
            Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::Null => 0.0,
            Bsdf::TwoSided(front, back) => twosided::eval_pdf(front, back, ctx, si, wo).1,
            Bsdf::Conductor(_) => 0.0,
            Bsdf::RoughConductor(b) => b.pdf(ctx, si, wo),
            Bsdf::Plastic(b) => b.eval_pdf(ctx, si, wo).1,
            Bsdf::RoughPlastic(b) => b.eval_pdf(ctx, si, wo).1,
            Bsdf::Mask(b) => b.eval_pdf(ctx, si, wo).1,
        }
    }

    /// [`Bsdf::eval_pdf`] with the `diffuse` model built into the caller and the other models
    /// called (the same results; see [`Bsdf::sample_inline`]).
    #[inline(always)]
    pub fn eval_pdf_inline(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        match self {
            Bsdf::Diffuse(b) => (b.eval(ctx, si, wo), b.pdf(ctx, si, wo)),
            _ => self.eval_pdf(ctx, si, wo),
        }
    }

    /// [`eval`](Self::eval) and [`pdf`](Self::pdf) together.
    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        match self {
            Bsdf::Diffuse(b) => (b.eval(ctx, si, wo), b.pdf(ctx, si, wo)),
            Bsdf::RoughDielectric(b) => b.eval_pdf(ctx, si, wo),
            Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::Null => (Spectrum::ZERO, 0.0),
            Bsdf::TwoSided(front, back) => twosided::eval_pdf(front, back, ctx, si, wo),
            Bsdf::Conductor(_) => (Spectrum::ZERO, 0.0),
            Bsdf::RoughConductor(b) => b.eval_pdf(ctx, si, wo),
            Bsdf::Plastic(b) => b.eval_pdf(ctx, si, wo),
            Bsdf::RoughPlastic(b) => b.eval_pdf(ctx, si, wo),
            Bsdf::Mask(b) => b.eval_pdf(ctx, si, wo),
        }
    }

    /// Transmission through a NULL-flagged component along the ray (null: 1; thindielectric: its straight transmission), else 0.
    pub fn eval_null_transmission(&self, si: &SurfaceInteraction) -> Spectrum {
        match self {
            Bsdf::Null => Spectrum::ONE,
            Bsdf::ThinDielectric(b) => b.eval_null_transmission(si),
            Bsdf::Mask(b) => b.eval_null_transmission(si),
            // Mitsuba's twosided does not forward this (it only nests non-transmissive models by default).
            _ => Spectrum::ZERO,
        }
    }
}

/// A model's sample as [`Bsdf::sample`] returns it: `None` unless the pdf and the weight are positive.
#[inline(always)]
fn nonzero(sample: Option<(BsdfSample, Spectrum)>) -> Option<(BsdfSample, Spectrum)> {
    let (bs, weight) = sample?;
    (bs.pdf > 0.0 && weight.max_element() > 0.0).then_some((bs, weight))
}

/// An optional reflectance-like texture (`specular_reflectance`, ...): `None` when absent, as
/// Mitsuba only multiplies by it when given.
pub(crate) fn optional_texture(props: &Props, name: &str, resolver: &FileResolver) -> Result<Option<Texture>> {
    if !props.has(name) {
        return Ok(None);
    }
    let arg = props.texture(name, Spectrum::ONE)?;
    Ok(Some(Texture::from_arg(&arg, resolver)?))
}

/// `int_ior` / `ext_ior` (names or numbers, defaults bk7 / air), both non-negative.
pub(crate) fn read_iors(props: &Props) -> Result<(f32, f32)> {
    let int_ior = props.ior("int_ior", "bk7")?;
    let ext_ior = props.ior("ext_ior", "air")?;
    for (name, v) in [("int_ior", int_ior), ("ext_ior", ext_ior)] {
        if v.is_nan() || v < 0.0 || v.is_infinite() {
            return Err(props.error(
                name,
                format!(
                    "{}: the interior and exterior indices of refraction must be positive (got {} = {})",
                    props.describe_owner(),
                    name,
                    v
                ),
            ));
        }
    }
    Ok((int_ior, ext_ior))
}

/// Multiply by an optional texture evaluated at the hit.
#[inline]
pub(crate) fn times_texture(value: Spectrum, tex: &Option<Texture>, si: &SurfaceInteraction) -> Spectrum {
    match tex {
        Some(t) => value * t.eval(si.uv),
        None => value,
    }
}

/// A texture read as one number, as Mitsuba's `eval_1` does in RGB mode: a constant gives the mean
/// of its channels, a bitmap (and here any other texture) the luminance of its colour.
#[inline]
pub(crate) fn eval_1(tex: &Texture, uv: Vec2) -> f32 {
    match tex {
        Texture::Const(c) if c.x == c.y && c.y == c.z => c.x,
        Texture::Const(c) => (c.x + c.y + c.z) / 3.0,
        t => crate::color::luminance(t.eval(uv)),
    }
}
