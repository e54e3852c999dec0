//! Plugins one at a time, against Mitsuba 3.9.1 and against their own pdfs: BSDFs (`bsdf`,
//! `bsdf_surfaces`), emitters (`emitters`), shapes as area lights (`shapes`), textures and image
//! files (`textures`, `bitmap_formats`), sensors and films (`sensor`, `film`), shading frames of
//! ray hits (`shading_frame`).
//!
//! Mitsuba's numbers are JSON files in `tests/data/`, each written by a script in `scripts/`
//! (named in the test module that reads it), rounded to 9 or 10 significant digits (round-trip
//! exact for f32; the image blocks of `sensor.json` to 8, as Mitsuba's f32 sums are printed).

mod bitmap_formats;
mod bsdf;
mod bsdf_surfaces;
mod emitters;
mod film;
mod sensor;
mod shading_frame;
mod shapes;
mod textures;

#[path = "../common/mod.rs"]
mod common;

use serde_json::Value as Json;
use snee::bsdf::Bsdf;
use snee::math::{Vec2, Vec3};
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::resolver::FileResolver;
use snee::scene::SrcPos;
use std::path::PathBuf;

// ---- Mitsuba's values (JSON files in tests/data/) ----

/// `tests/data`.
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// `tests/data/NAME`, parsed.
pub fn mitsuba_json(name: &str) -> Json {
    let path = data_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON number as f32 (the tables hold f32 values printed with enough digits to round-trip).
pub fn num(v: &Json) -> f32 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}")) as f32
}

/// A JSON array of numbers as `[f32; N]`.
pub fn nums<const N: usize>(v: &Json) -> [f32; N] {
    let a = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    assert_eq!(a.len(), N, "{v}");
    std::array::from_fn(|i| num(&a[i]))
}

pub fn vec2(v: &Json) -> Vec2 {
    Vec2::from_array(nums(v))
}

pub fn vec3(v: &Json) -> Vec3 {
    Vec3::from_array(nums(v))
}

pub fn uint(v: &Json) -> u32 {
    v.as_u64().and_then(|x| u32::try_from(x).ok()).unwrap_or_else(|| panic!("not a u32: {v}"))
}

/// A 4 × 4 matrix as rows (Mitsuba's print order).
pub fn rows4(v: &Json) -> [[f64; 4]; 4] {
    let rows = v.as_array().unwrap_or_else(|| panic!("not a matrix: {v}"));
    std::array::from_fn(|r| std::array::from_fn(|c| rows[r][c].as_f64().unwrap()))
}

/// A transform property from Mitsuba's row-major matrix.
pub fn transform(rows: [[f64; 4]; 4]) -> Value {
    Value::Transform(glam::DMat4::from_cols_array_2d(&rows).transpose())
}

// ---- BSDFs ----

/// A BSDF description with every property at `test.xml:1:1`.
pub fn bsdf_desc(plugin: &str, props: Vec<(&str, Value)>) -> ObjectDesc {
    let pos = SrcPos::new("test.xml", 1, 1);
    let mut p = Props::new(PluginKind::Bsdf, plugin, pos.clone());
    for (name, v) in props {
        p.push(name, v, pos.clone()).unwrap();
    }
    ObjectDesc { kind: PluginKind::Bsdf, plugin: plugin.to_string(), id: None, pos, props: p }
}

pub fn load_bsdf(plugin: &str, props: Vec<(&str, Value)>) -> Bsdf {
    Bsdf::from_desc(&bsdf_desc(plugin, props), &FileResolver::default()).unwrap()
}

/// |a − b| ≤ abs + rel · max(|a|, |b|).
pub fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= abs + rel * a.abs().max(b.abs())
}

/// Mitsuba's Beckmann masking G1 is a rational fit (< 0.35% error) while its visible-normal
/// sampler inverts the exact distribution, so the Beckmann visible-normal pdf is the exact one
/// times K = G1_fit(wi) / G1_exact(wi) (G1 does not depend on m on the visible side). This is
/// Mitsuba's behaviour, reproduced on purpose; the tests divide it out so that the missing-mass
/// cell still checks the rest to full precision. K = 1 for GGX (exact Smith).
pub fn beckmann_visible_pdf_scale(alpha_u: f32, alpha_v: f32, wi: Vec3) -> f64 {
    use snee::bsdf::microfacet::{erf, MicrofacetDistribution, MicrofacetType};
    let wi_up = if wi.z < 0.0 { -wi } else { wi };
    let distr = MicrofacetDistribution::new(MicrofacetType::Beckmann, alpha_u, alpha_v, true);
    let g1_fit = distr.smith_g1(wi_up, Vec3::Z) as f64;
    let (x, y, z) = (wi_up.x as f64, wi_up.y as f64, wi_up.z as f64);
    let a = z / ((alpha_u as f64 * x).powi(2) + (alpha_v as f64 * y).powi(2)).sqrt();
    let g1_exact = 2.0 / (1.0 + erf(a as f32) as f64 + (-a * a).exp() / (a * std::f64::consts::PI.sqrt()));
    g1_fit / g1_exact
}

/// Chi-square of `bsdf.sample` against `bsdf.pdf / pdf_scale` for one `wi`, on a 24 × `res_phi`
/// grid with `samples` draws. With `skip_singular`, delta and null samples count as missing mass
/// (they are not part of the density: the surface BSDFs with a smooth coating or `mask`).
pub struct BsdfChi2 {
    pub pdf_scale: f64,
    pub res_phi: usize,
    pub samples: usize,
    pub skip_singular: bool,
}

impl Default for BsdfChi2 {
    fn default() -> Self {
        BsdfChi2 { pdf_scale: 1.0, res_phi: 48, samples: 100_000, skip_singular: false }
    }
}

impl BsdfChi2 {
    pub fn run(
        &self,
        bsdf: &Bsdf,
        ctx: &snee::bsdf::BsdfContext,
        wi: Vec3,
        significance: f64,
        seed: u64,
    ) -> snee::testing::chi2::Chi2Result {
        use snee::bsdf::flags;
        let si = snee::testing::si_with_wi(wi);
        let singular = if self.skip_singular { flags::DELTA | flags::NULL } else { 0 };
        snee::testing::chi2::chi2_sphere(
            |u1, u2| {
                bsdf.sample(ctx, &si, u1, u2).filter(|(bs, _)| bs.sampled_type & singular == 0).map(|(bs, _)| bs.wo)
            },
            |wo| (bsdf.pdf(ctx, &si, wo) as f64 / self.pdf_scale) as f32,
            24,
            self.res_phi,
            self.samples,
            significance,
            seed,
        )
    }
}
