//! The `<sampler>` of a sensor: sample count per pixel and seed.
//!
//! | type          | parameters                                            |
//! |---------------|-------------------------------------------------------|
//! | `independent` | `sample_count` (default 4), `seed` (default 0)        |
//! | `stratified`  | as above, plus `jitter` (boolean, default true)       |
//! | `multijitter` | as above, plus `jitter` (boolean, default true)       |
//!
//! Mitsuba rounds the sample count of the stratified sampler up to a square (5 → 9) and that of
//! the multijitter sampler up to `ceil(n / ⌊√n⌋)·⌊√n⌋` (5 → 6, 32 → 35); `sample_count` here is
//! the rounded value, which is the number of samples Mitsuba takes. Rendering currently draws
//! independent samples for all three kinds.
//!
//! ```xml
//! <sampler type="independent">
//!     <integer name="sample_count" value="64"/>
//!     <integer name="seed" value="7"/>
//! </sampler>
//! ```

use crate::scene::desc::ObjectDesc;
use crate::scene::error::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    Independent,
    Stratified,
    Multijitter,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerDesc {
    pub kind: SamplerKind,
    /// Samples per pixel, after Mitsuba's rounding for stratified and multijitter.
    pub sample_count: u32,
    pub seed: u64,
}

impl Default for SamplerDesc {
    /// What Mitsuba uses when a sensor has no sampler: independent, 4 samples per pixel.
    fn default() -> Self {
        SamplerDesc { kind: SamplerKind::Independent, sample_count: 4, seed: 0 }
    }
}

impl SamplerDesc {
    /// Parse a `<sampler>` object.
    pub fn from_desc(obj: &ObjectDesc) -> Result<SamplerDesc> {
        let props = &obj.props;
        let kind = match obj.plugin.as_str() {
            "independent" => SamplerKind::Independent,
            "stratified" => SamplerKind::Stratified,
            "multijitter" => SamplerKind::Multijitter,
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!(
                        "sampler type \"{other}\" is not supported (supported: independent, stratified, multijitter)"
                    ),
                ))
            }
        };
        let count = props.int("sample_count", 4)?;
        if !(1..=(1 << 24)).contains(&count) {
            return Err(
                props.error("sample_count", format!("\"sample_count\" must be between 1 and 2^24, got {count}"))
            );
        }
        let seed = props.int("seed", 0)?;
        if !(0..=u32::MAX as i64).contains(&seed) {
            return Err(props.error("seed", format!("\"seed\" must be a non-negative 32-bit integer, got {seed}")));
        }
        if kind != SamplerKind::Independent {
            // Accepted for compatibility; rendering draws independent samples for now.
            props.bool("jitter", true)?;
        }
        props.finish()?;
        let count = count as u32;
        let sample_count = match kind {
            SamplerKind::Independent => count,
            SamplerKind::Stratified => {
                let res = (1..).find(|r: &u32| r * r >= count).unwrap_or(count);
                res * res
            }
            SamplerKind::Multijitter => {
                let rows = ((count as f32).sqrt() as u32).max(1);
                count.div_ceil(rows) * rows
            }
        };
        Ok(SamplerDesc { kind, sample_count, seed: seed as u64 })
    }
}
