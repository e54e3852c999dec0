//! Partial renders and their exact merging (`snee render --sample-range`, `--checkpoint`,
//! `--resume`, `snee merge`).
//!
//! A *part* is an image that holds samples `START..END` of every pixel of a run defined by a
//! scene, its `-D` defines, the integrator, the seed and the run's total samples per pixel
//! (`spp`). Because the sampler stream of sample `i` of a pixel depends only on the pixel, `i`
//! and the seed (`render` module), disjoint parts of one run are pieces of the same single-process
//! render and add up to it.
//!
//! On disk a part is an ordinary float32 EXR whose colour channels (`R, G, B[, A]`, `m2.*` with
//! `--moment`) hold the developed means, plus
//! - a channel `W`: the pixel's accumulated reconstruction-filter weight, so `value × W` is the
//!   pixel's weighted sum of samples (for a box filter, `W` is the sample count);
//! - a header text attribute `snee`: JSON [`PartMeta`] (format, scene file and fingerprint,
//!   defines, integrator, seed, spp, sample range, film size and crop window, moment on/off).
//!
//! Merging adds the weighted sums and the weights per pixel and channel (in f64) and divides:
//! `v = Σ_k v_k·W_k / Σ_k W_k` — the spp-weighted mean of the means and of the second moments,
//! equal to the single run up to float summation order. Parts must agree on everything but
//! the range, and their ranges must be disjoint; `merge` names the missing ranges.
//!
//! [`PartRender`] is the render side: the metadata of a `--sample-range`/`--checkpoint`/`--resume`
//! render, the samples it still has to take, and writing checkpoints and the final part (the
//! resumed part merged with the new samples).

use crate::integrator::IntegratorKind;
use crate::render::RenderOutput;
use anyhow::{anyhow, bail, Context};
use serde_json::{json, Value};
use std::path::Path;

/// Value of the `format` field; bump when the layout changes.
pub const FORMAT: &str = "snee-part/1";
/// Name of the header attribute holding [`PartMeta`] as JSON.
pub const ATTRIBUTE: &str = "snee";
/// Name of the per-pixel filter-weight channel.
pub const WEIGHT_CHANNEL: &str = "W";

/// What a part is a piece of, and which piece.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartMeta {
    /// Scene file as given on the command line (informative: runs on several machines may see
    /// different paths; consistency is checked on `scene_hash`).
    pub scene: String,
    /// FNV-1a 64 of the scene file's bytes and the defines ([`scene_fingerprint`]), hex.
    pub scene_hash: String,
    pub defines: Vec<(String, String)>,
    /// Integrator plugin name (`path`, `volpath`, `volpathmis`, `volpath_snee`).
    pub integrator: String,
    pub seed: u64,
    /// Samples per pixel of the whole run.
    pub spp: u32,
    /// The part holds samples `range.0..range.1` of every pixel.
    pub range: (u32, u32),
    /// Film width, height.
    pub film: (u32, u32),
    /// Crop window: offset x, y, size x, y.
    pub crop: [u32; 4],
    /// Second moments (`m2.*` channels) present.
    pub moment: bool,
    /// Transport-class channel groups (`--classes`) present.
    pub classes: bool,
    /// snee version that rendered the part (informative).
    pub version: String,
}

impl PartMeta {
    pub fn to_json(&self) -> Value {
        json!({
            "format": FORMAT,
            "scene": self.scene,
            "scene_hash": self.scene_hash,
            "defines": self.defines.iter().map(|(k, v)| json!([k, v])).collect::<Vec<_>>(),
            "integrator": self.integrator,
            "seed": self.seed,
            "spp": self.spp,
            "range": [self.range.0, self.range.1],
            "film": [self.film.0, self.film.1],
            "crop": self.crop,
            "moment": self.moment,
            "classes": self.classes,
            "version": self.version,
        })
    }

    pub fn from_json(v: &Value) -> Result<PartMeta, String> {
        let format = v["format"].as_str().ok_or("no \"format\" field")?;
        if format != FORMAT {
            return Err(format!("format \"{format}\", expected \"{FORMAT}\""));
        }
        let s = |k: &str| v[k].as_str().map(str::to_string).ok_or(format!("field \"{k}\" missing or not a string"));
        let u = |x: &Value, k: &str| x.as_u64().ok_or(format!("field \"{k}\" missing or not a non-negative integer"));
        let u32_of =
            |x: &Value, k: &str| u(x, k).and_then(|n| u32::try_from(n).map_err(|_| format!("\"{k}\" too large")));
        let pair = |k: &str| -> Result<(u32, u32), String> {
            let a = v[k].as_array().filter(|a| a.len() == 2).ok_or(format!("field \"{k}\" is not a pair"))?;
            Ok((u32_of(&a[0], k)?, u32_of(&a[1], k)?))
        };
        let crop_list = v["crop"].as_array().filter(|a| a.len() == 4).ok_or("field \"crop\" is not 4 integers")?;
        let mut crop = [0u32; 4];
        for (c, x) in crop.iter_mut().zip(crop_list) {
            *c = u32_of(x, "crop")?;
        }
        let defines = v["defines"]
            .as_array()
            .ok_or("field \"defines\" is not a list")?
            .iter()
            .map(|d| match d.as_array().map(|a| a.as_slice()) {
                Some([Value::String(k), Value::String(val)]) => Ok((k.clone(), val.clone())),
                _ => Err("a define is not a [name, value] pair".to_string()),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let range = pair("range")?;
        if range.0 > range.1 {
            return Err(format!("range {}..{} is reversed", range.0, range.1));
        }
        Ok(PartMeta {
            scene: s("scene")?,
            scene_hash: s("scene_hash")?,
            defines,
            integrator: s("integrator")?,
            seed: u(&v["seed"], "seed")?,
            spp: u32_of(&v["spp"], "spp")?,
            range,
            film: pair("film")?,
            crop,
            moment: v["moment"].as_bool().ok_or("field \"moment\" missing or not a boolean")?,
            // Absent in parts written before `--classes` existed.
            classes: v["classes"].as_bool().unwrap_or(false),
            version: s("version").unwrap_or_default(),
        })
    }

    /// `Err` naming the first field (other than the range) in which `other` differs.
    pub fn check_same_run(&self, other: &PartMeta) -> Result<(), String> {
        let fields: [(&str, String, String); 8] = [
            ("scene (file contents and -D defines)", self.scene_hash.clone(), other.scene_hash.clone()),
            ("integrator", self.integrator.clone(), other.integrator.clone()),
            ("seed", self.seed.to_string(), other.seed.to_string()),
            ("spp", self.spp.to_string(), other.spp.to_string()),
            ("film size", format!("{}x{}", self.film.0, self.film.1), format!("{}x{}", other.film.0, other.film.1)),
            ("crop window", format!("{:?}", self.crop), format!("{:?}", other.crop)),
            ("moment", self.moment.to_string(), other.moment.to_string()),
            ("classes", self.classes.to_string(), other.classes.to_string()),
        ];
        for (name, a, b) in fields {
            if a != b {
                return Err(format!("{name} differs: {a} vs {b}"));
            }
        }
        Ok(())
    }
}

/// FNV-1a 64-bit hash of the scene file's bytes and the `-D` defines, as 16 hex digits: the
/// identity of a run's scene across machines (files the scene references are not included).
pub fn scene_fingerprint(path: &Path, defines: &[(String, String)]) -> anyhow::Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |data: &[u8]| {
        for &b in data {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    eat(&bytes);
    for (k, v) in defines {
        eat(&[0]);
        eat(k.as_bytes());
        eat(b"=");
        eat(v.as_bytes());
    }
    Ok(format!("{h:016x}"))
}

/// The Mitsuba plugin name of an integrator.
pub fn integrator_name(kind: IntegratorKind) -> &'static str {
    match kind {
        IntegratorKind::Path => "path",
        IntegratorKind::Volpath => "volpath",
        IntegratorKind::Volpathmis => "volpathmis",
        IntegratorKind::VolpathSnee => "volpath_snee",
    }
}

/// A partial (or complete) render with its weights and metadata.
#[derive(Clone, Debug)]
pub struct Part {
    /// Where the part came from (a file name), for messages.
    pub source: String,
    pub meta: PartMeta,
    pub width: usize,
    pub height: usize,
    /// Value channels (without `W`).
    pub channels: Vec<String>,
    /// Developed means, channels interleaved, row 0 at the top.
    pub data: Vec<f32>,
    /// Filter weight per pixel.
    pub weights: Vec<f32>,
}

impl Part {
    /// The part a render produced; `meta.range` is set from the render's samples.
    pub fn from_render(source: &str, mut meta: PartMeta, out: &RenderOutput) -> Part {
        meta.range = (out.first_sample, out.first_sample + out.stats.spp);
        Part {
            source: source.to_string(),
            meta,
            width: out.width,
            height: out.height,
            channels: out.channels.clone(),
            data: out.data.clone(),
            weights: out.weights.clone(),
        }
    }

    /// Read a part written by [`Part::write`]: an error naming the file when it is not an EXR,
    /// has no `snee` metadata or no `W` channel, or its metadata is malformed.
    pub fn read(path: &Path) -> anyhow::Result<Part> {
        let source = path.display().to_string();
        let text = crate::io::meta::read_exr_text_attribute(path, ATTRIBUTE)?.ok_or_else(|| {
            anyhow!("{source}: no \"{ATTRIBUTE}\" metadata: not a partial render (render it with --sample-range, --checkpoint or --resume)")
        })?;
        let json: Value =
            serde_json::from_str(&text).map_err(|e| anyhow!("{source}: \"{ATTRIBUTE}\" metadata is not JSON: {e}"))?;
        let meta = PartMeta::from_json(&json).map_err(|e| anyhow!("{source}: \"{ATTRIBUTE}\" metadata: {e}"))?;
        let bitmap = crate::io::read::read_image(path, false)?;
        let nc = bitmap.channels.len();
        let w = bitmap.channel(WEIGHT_CHANNEL).ok_or_else(|| anyhow!("{source}: no \"{WEIGHT_CHANNEL}\" channel"))?;
        // Keep the render's channel order (R, G, B, [A], [m2.*]); EXR stores channels sorted by name.
        let mut order: Vec<usize> = (0..nc).filter(|&c| c != w).collect();
        order.sort_by_key(|&c| channel_rank(&bitmap.channels[c]));
        let channels: Vec<String> = order.iter().map(|&c| bitmap.channels[c].clone()).collect();
        let mut data = Vec::with_capacity(bitmap.width * bitmap.height * order.len());
        let mut weights = Vec::with_capacity(bitmap.width * bitmap.height);
        for px in bitmap.data.chunks_exact(nc) {
            data.extend(order.iter().map(|&c| px[c]));
            let wt = px[w];
            if !(wt >= 0.0 && wt.is_finite()) {
                bail!("{source}: channel \"{WEIGHT_CHANNEL}\" holds {wt}, expected finite weights >= 0");
            }
            weights.push(wt);
        }
        if meta.film.0 == 0 || (meta.crop[2] as usize, meta.crop[3] as usize) != (bitmap.width, bitmap.height) {
            bail!(
                "{source}: image is {}x{}, its metadata says the crop window is {}x{}",
                bitmap.width,
                bitmap.height,
                meta.crop[2],
                meta.crop[3]
            );
        }
        Ok(Part { source, meta, width: bitmap.width, height: bitmap.height, channels, data, weights })
    }

    /// Write the part as an EXR with the `W` channel and the `snee` metadata (atomically).
    pub fn write(&self, path: &Path) -> anyhow::Result<()> {
        let (names, data) = self.with_weight_channel();
        let names: Vec<&str> = names.iter().map(|s| s.as_str()).collect();
        let meta = self.meta.to_json().to_string();
        crate::io::write::write_exr_with_attributes(path, self.width, self.height, &names, &data, &[(ATTRIBUTE, &meta)])
    }

    fn with_weight_channel(&self) -> (Vec<String>, Vec<f32>) {
        let mut names = self.channels.clone();
        names.push(WEIGHT_CHANNEL.to_string());
        let n = self.channels.len().max(1);
        let data = self.data.chunks(n).zip(&self.weights).flat_map(|(px, &w)| px.iter().copied().chain([w])).collect();
        (names, data)
    }
}

/// Sort key putting channels in render order: R, G, B, A, m2.R, m2.G, m2.B, then the rest by name.
fn channel_rank(name: &str) -> (usize, String) {
    const ORDER: [&str; 7] = ["R", "G", "B", "A", "m2.R", "m2.G", "m2.B"];
    let rank = ORDER.iter().position(|c| *c == name).unwrap_or(ORDER.len());
    (rank, name.to_string())
}

/// The sample ranges of `0..spp` that none of `ranges` covers, in order.
pub fn missing_ranges(ranges: &[(u32, u32)], spp: u32) -> Vec<(u32, u32)> {
    let mut sorted: Vec<(u32, u32)> = ranges.iter().copied().filter(|r| r.0 < r.1).collect();
    sorted.sort();
    let mut missing = Vec::new();
    let mut at = 0u32;
    for (s, e) in sorted {
        if s > at {
            missing.push((at, s));
        }
        at = at.max(e);
    }
    if at < spp {
        missing.push((at, spp));
    }
    missing
}

fn format_ranges(ranges: &[(u32, u32)]) -> String {
    ranges.iter().map(|(s, e)| format!("{s}..{e}")).collect::<Vec<_>>().join(", ")
}

/// Merge parts of one run into one part: the spp-weighted means (and second moments) per pixel.
/// The parts must agree on scene, integrator, seed, spp, film, moment and channels, and have
/// disjoint sample ranges whose union is one range; unless `allow_partial`, that range must be
/// the whole run `0..spp`. Errors name the parts and the missing or overlapping ranges.
pub fn merge(parts: &[Part], allow_partial: bool) -> anyhow::Result<Part> {
    let Some(first) = parts.first() else { bail!("nothing to merge") };
    for p in &parts[1..] {
        first.meta.check_same_run(&p.meta).map_err(|e| anyhow!("{} and {}: {e}", first.source, p.source))?;
        if (p.width, p.height) != (first.width, first.height) || p.channels != first.channels {
            bail!(
                "{} and {}: images differ in size or channels ({}x{} [{}] vs {}x{} [{}])",
                first.source,
                p.source,
                first.width,
                first.height,
                first.channels.join(", "),
                p.width,
                p.height,
                p.channels.join(", ")
            );
        }
    }
    // Disjoint ranges.
    let mut order: Vec<&Part> = parts.iter().filter(|p| p.meta.range.0 < p.meta.range.1).collect();
    order.sort_by_key(|p| p.meta.range);
    for pair in order.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if b.meta.range.0 < a.meta.range.1 {
            bail!(
                "{} (samples {}..{}) and {} (samples {}..{}) overlap: parts must hold disjoint sample ranges",
                a.source,
                a.meta.range.0,
                a.meta.range.1,
                b.source,
                b.meta.range.0,
                b.meta.range.1
            );
        }
    }
    let ranges: Vec<(u32, u32)> = order.iter().map(|p| p.meta.range).collect();
    let spp = first.meta.spp;
    let union = match (ranges.first(), ranges.last()) {
        (Some(a), Some(b)) => (a.0, b.1),
        _ => (first.meta.range.0, first.meta.range.0),
    };
    let gaps: Vec<(u32, u32)> =
        missing_ranges(&ranges, spp).into_iter().filter(|r| r.0 >= union.0 && r.1 <= union.1).collect();
    let missing = missing_ranges(&ranges, spp);
    if !allow_partial && !missing.is_empty() {
        bail!(
            "samples {} of {spp} per pixel are missing (the parts hold {}); render them with --sample-range, or merge with --partial",
            format_ranges(&missing),
            format_ranges(&ranges)
        );
    }
    if !gaps.is_empty() {
        bail!(
            "the parts leave gaps: samples {} missing (the parts hold {})",
            format_ranges(&gaps),
            format_ranges(&ranges)
        );
    }
    let n = first.channels.len();
    let pixels = first.width * first.height;
    let mut data = vec![0.0f32; pixels * n];
    let mut weights = vec![0.0f32; pixels];
    let mut sums = vec![0.0f64; n];
    for i in 0..pixels {
        sums.fill(0.0);
        let mut weight = 0.0f64;
        for p in parts {
            let w = p.weights[i] as f64;
            weight += w;
            for (s, v) in sums.iter_mut().zip(&p.data[i * n..(i + 1) * n]) {
                *s += *v as f64 * w;
            }
        }
        let inv = if weight > 0.0 { 1.0 / weight } else { 0.0 };
        for (d, s) in data[i * n..(i + 1) * n].iter_mut().zip(&sums) {
            *d = (s * inv) as f32;
        }
        weights[i] = weight as f32;
    }
    let mut meta = first.meta.clone();
    meta.range = union;
    Ok(Part {
        source: parts.iter().map(|p| p.source.as_str()).collect::<Vec<_>>().join(" + "),
        meta,
        width: first.width,
        height: first.height,
        channels: first.channels.clone(),
        data,
        weights,
    })
}

/// A render that produces a part (`--sample-range`, `--checkpoint`, `--resume`): its metadata,
/// the target sample range, and the partial image it continues (checked to belong to the run).
pub struct PartRender {
    pub meta: PartMeta,
    /// Samples this run completes: `range.0..range.1` of every pixel.
    pub range: (u32, u32),
    resumed: Option<Part>,
}

impl PartRender {
    pub fn new(
        scene_path: &Path,
        defines: &[(String, String)],
        scene: &crate::scene::world::Scene,
        opts: &crate::render::RenderOptions,
        sample_range: Option<(u32, u32)>,
        resume: Option<&Path>,
    ) -> anyhow::Result<PartRender> {
        let spp = crate::render::total_spp(scene, opts);
        if spp == u32::MAX {
            return Err(anyhow!(
                "--sample-range, --checkpoint and --resume need a sample count: give --spp (with --time the render stops at whichever comes first)"
            ));
        }
        let range = sample_range.unwrap_or((0, spp));
        if range.1 > spp {
            return Err(anyhow!("--sample-range {}..{}: the run has {spp} samples per pixel", range.0, range.1));
        }
        let film = &scene.film;
        let meta = PartMeta {
            scene: scene_path.display().to_string(),
            scene_hash: scene_fingerprint(scene_path, defines)?,
            defines: defines.to_vec(),
            integrator: integrator_name(scene.integrator.kind).to_string(),
            seed: opts.seed,
            spp,
            range,
            film: (film.width, film.height),
            crop: [film.crop_offset.0, film.crop_offset.1, film.crop_size.0, film.crop_size.1],
            moment: scene.integrator.moment,
            classes: scene.integrator.classes,
            version: env!("CARGO_PKG_VERSION").to_string(),
        };
        let resumed = match resume {
            None => None,
            Some(path) => {
                let part = Part::read(path)?;
                meta.check_same_run(&part.meta)
                    .map_err(|e| anyhow!("--resume {}: not a part of this render: {e}", path.display()))?;
                let (s, e) = part.meta.range;
                if s != range.0 || e > range.1 {
                    return Err(anyhow!(
                        "--resume {}: holds samples {s}..{e}, which is not a start of the samples {}..{} to render",
                        path.display(),
                        range.0,
                        range.1
                    ));
                }
                Some(part)
            }
        };
        Ok(PartRender { meta, range, resumed })
    }

    /// The first sample this process renders.
    pub fn next_sample(&self) -> u32 {
        self.resumed.as_ref().map_or(self.range.0, |p| p.meta.range.1)
    }

    /// The resumed part (if any) plus `new`.
    fn combine(&self, new: Part) -> anyhow::Result<Part> {
        match &self.resumed {
            Some(old) => merge(&[old.clone(), new], true),
            None => Ok(new),
        }
    }

    pub fn write_checkpoint(&self, output: &Path, state: &crate::render::PassState) -> anyhow::Result<()> {
        let (width, height) = (self.meta.crop[2] as usize, self.meta.crop[3] as usize);
        let new = Part {
            source: "checkpoint".into(),
            meta: PartMeta { range: state.samples, ..self.meta.clone() },
            width,
            height,
            channels: state.channels.to_vec(),
            data: state.develop(),
            weights: state.weights(),
        };
        create_parent(output)?;
        self.combine(new)?.write(output)
    }

    pub fn write_final(&self, output: &Path, out: &crate::render::RenderOutput, png: bool) -> anyhow::Result<()> {
        let part = self.combine(Part::from_render("render", self.meta.clone(), out))?;
        create_parent(output)?;
        part.write(output)?;
        if png {
            let n = part.channels.len();
            let rgb: Vec<f32> = part.data.chunks(n).flat_map(|p| [p[0], p[1], p[2]]).collect();
            crate::io::write::write_png(&output.with_extension("png"), part.width, part.height, &rgb)?;
        }
        Ok(())
    }
}

fn create_parent(path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating the folder {}", dir.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta(range: (u32, u32)) -> PartMeta {
        PartMeta {
            scene: "s.xml".into(),
            scene_hash: "00".into(),
            defines: vec![("a".into(), "1".into())],
            integrator: "path".into(),
            seed: 3,
            spp: 10,
            range,
            film: (2, 1),
            crop: [0, 0, 2, 1],
            moment: false,
            classes: false,
            version: "x".into(),
        }
    }

    fn part(name: &str, range: (u32, u32), values: [f32; 2], weights: [f32; 2]) -> Part {
        Part {
            source: name.into(),
            meta: meta(range),
            width: 2,
            height: 1,
            channels: vec!["Y".into()],
            data: values.to_vec(),
            weights: weights.to_vec(),
        }
    }

    #[test]
    fn meta_json_round_trip() {
        let m = meta((2, 7));
        assert_eq!(PartMeta::from_json(&m.to_json()).unwrap(), m);
        let mut bad = m.to_json();
        bad["range"] = json!([7, 2]);
        assert!(PartMeta::from_json(&bad).is_err());
    }

    #[test]
    fn weighted_mean_of_parts() {
        let a = part("a", (0, 4), [1.0, 0.0], [4.0, 0.0]);
        let b = part("b", (4, 10), [2.0, 3.0], [6.0, 6.0]);
        let m = merge(&[b, a], false).unwrap();
        assert_eq!(m.data, [1.6, 3.0]);
        assert_eq!(m.weights, [10.0, 6.0]);
        assert_eq!(m.meta.range, (0, 10));
    }

    #[test]
    fn gaps_overlaps_and_mismatches_are_named() {
        let a = part("a", (0, 4), [1.0; 2], [1.0; 2]);
        let c = part("c", (6, 9), [1.0; 2], [1.0; 2]);
        let e = merge(&[a.clone(), c.clone()], false).unwrap_err().to_string();
        assert!(e.contains("4..6") && e.contains("9..10"), "{e}");
        let e = merge(&[a.clone(), part("b", (3, 10), [1.0; 2], [1.0; 2])], false).unwrap_err().to_string();
        assert!(e.contains("overlap") && e.contains("3..10"), "{e}");
        let mut d = part("d", (4, 10), [1.0; 2], [1.0; 2]);
        d.meta.seed = 4;
        let e = merge(&[a.clone(), d], false).unwrap_err().to_string();
        assert!(e.contains("seed"), "{e}");
        let m = merge(&[part("x", (4, 5), [1.0; 2], [1.0; 2]), c], true).unwrap_err().to_string();
        assert!(m.contains("gaps") && m.contains("5..6"), "{m}");
        assert_eq!(merge(&[a], true).unwrap().meta.range, (0, 4));
        assert_eq!(missing_ranges(&[(2, 3), (5, 6)], 7), [(0, 2), (3, 5), (6, 7)]);
    }
}
