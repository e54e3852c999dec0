//! `snee info`: a scene summary (plugins as a tree, triangle count, bounds, media, emitters,
//! film and samples), as text or JSON, in the scene's words: plugin and parameter names as in the
//! XML (`volpath_snee`, `sigma_t`, `max_depth`), colours as one number when grey.
//!
//! ```text
//! scene
//!   integrator volpath
//!   shape ply
//!     bsdf dielectric
//!     medium homogeneous (interior) id="smoke"
//! shapes: 2, triangles: 1282
//! bounds: (-4, 0, -4) to (4, 1.3, 4)
//! media: 1
//!   medium "smoke": homogeneous, sigma_t = 2.5, albedo = 0.8, phase isotropic
//! emitters: 1 [envmap]
//! film: 96x72 hdrfilm, rgb, rfilter gaussian (crop 96x72 at 0, 0)
//! spp: 64 (independent)
//! integrator: volpath, max_depth = 64, rr_depth = 5, hide_emitters = false
//! ```

use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::integrator::desc::Integrator;
use crate::integrator::snee::{SneeTechnique, SneeTransport};
use crate::integrator::{IntegratorDesc, IntegratorKind};
use crate::medium::{Homogeneous, Phase};
use crate::scene::desc::{ObjectDesc, Value};
use crate::scene::world::{Scene, SceneEmitter};
use crate::scene::xml::ParsedScene;
use crate::sensor::film::PixelFormat;
use crate::sensor::rfilter::RFilter;
use crate::sensor::sampler_desc::SamplerKind;
use serde_json::{json, Value as Json};
use std::fmt::Write;

pub struct Summary {
    json: Json,
    text: String,
}

impl Summary {
    pub fn to_json(&self) -> Json {
        self.json.clone()
    }
    pub fn to_text(&self) -> String {
        self.text.clone()
    }
}

fn tree_json(obj: &ObjectDesc, name: Option<&str>) -> Json {
    let children: Vec<Json> = obj
        .props
        .items()
        .iter()
        .filter_map(|p| match &p.value {
            Value::Object(o) => Some(tree_json(o, given_name(&p.name))),
            _ => None,
        })
        .collect();
    json!({ "kind": obj.kind.tag(), "type": obj.plugin, "id": obj.id, "name": name, "children": children })
}

/// The `name` attribute of a nested object, unless it is the `_arg_N` given to unnamed ones.
fn given_name(name: &str) -> Option<&str> {
    (!name.is_empty() && !name.starts_with("_arg_")).then_some(name)
}

fn tree_text(obj: &ObjectDesc, name: Option<&str>, depth: usize, out: &mut String) {
    let _ = write!(out, "{}{}", "  ".repeat(depth), obj.kind.tag());
    if obj.plugin != obj.kind.tag() {
        let _ = write!(out, " {}", obj.plugin);
    }
    if let Some(n) = name {
        let _ = write!(out, " ({n})");
    }
    if let Some(id) = &obj.id {
        let _ = write!(out, " id=\"{id}\"");
    }
    out.push('\n');
    for p in obj.props.items() {
        if let Value::Object(o) = &p.value {
            tree_text(o, given_name(&p.name), depth + 1, out);
        }
    }
}

fn emitter_name(e: &SceneEmitter) -> &'static str {
    match e {
        SceneEmitter::Area { .. } => "area",
        SceneEmitter::Other(Emitter::Directional(..)) => "directional",
        SceneEmitter::Other(Emitter::Envmap(..)) => "envmap",
        SceneEmitter::Other(Emitter::Constant(..)) => "constant",
        SceneEmitter::Other(Emitter::Point(..)) => "point",
        SceneEmitter::Other(Emitter::Spot(..)) => "spot",
    }
}

/// The XML name of an integrator.
pub fn integrator_name(kind: IntegratorKind) -> &'static str {
    match kind {
        IntegratorKind::Path => "path",
        IntegratorKind::Volpath => "volpath",
        IntegratorKind::Volpathmis => "volpathmis",
        IntegratorKind::VolpathSnee => "volpath_snee",
    }
}

fn sampler_name(kind: SamplerKind) -> &'static str {
    match kind {
        SamplerKind::Independent => "independent",
        SamplerKind::Stratified => "stratified",
        SamplerKind::Multijitter => "multijitter",
    }
}

/// `0.8` for a grey colour, `(0.9, 0.8, 0.7)` otherwise.
fn color_text(c: Spectrum) -> String {
    let [r, g, b] = c.to_array();
    if r == g && g == b {
        num(r)
    } else {
        format!("({}, {}, {})", num(r), num(g), num(b))
    }
}

/// A number with up to 6 significant digits and no trailing zeros (`2.5`, `0.001`, `1e+08`).
fn num(v: f32) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !(1e-4..1e7).contains(&v.abs()) {
        return format!("{v:e}");
    }
    let t = format!("{:.*}", (5 - v.abs().log10().floor() as i32).max(0) as usize, v);
    if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    }
}

/// A coordinate to 4 decimals without trailing zeros (`-2.4e-16` reads `0`).
fn coord(v: f32) -> String {
    let t = format!("{v:.4}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" {
        "0".into()
    } else {
        t.into()
    }
}

fn phase_text(p: &Phase) -> String {
    match p {
        Phase::Isotropic => "isotropic".into(),
        Phase::Hg { g } => format!("hg (g = {})", num(*g)),
    }
}

fn medium_text(m: &Homogeneous) -> String {
    let id = m.id.as_ref().map_or_else(|| "medium (no id)".to_string(), |i| format!("medium \"{i}\""));
    format!(
        "{id}: homogeneous, sigma_t = {}, albedo = {}, phase {}",
        color_text(m.sigma_t),
        color_text(m.albedo),
        phase_text(&m.phase)
    )
}

fn rfilter_text(f: &RFilter) -> String {
    match f {
        RFilter::Gaussian { stddev } => format!("gaussian (stddev = {})", num(*stddev)),
        RFilter::Box => "box".into(),
        RFilter::Tent { radius } => format!("tent (radius = {})", num(*radius)),
    }
}

fn depth_text(d: i32) -> String {
    if d < 0 {
        "unbounded".into()
    } else {
        d.to_string()
    }
}

/// `volpath_snee`'s own parameters, as `snee = mis, transport = all, snee_rate = ...`.
fn snee_params(integ: &IntegratorDesc) -> Option<(&'static str, &'static str, Option<f32>)> {
    if integ.kind != IntegratorKind::VolpathSnee {
        return None;
    }
    let technique = match integ.snee.technique {
        SneeTechnique::Mis => "mis",
        SneeTechnique::Snee => "snee",
        SneeTechnique::Forward => "forward",
    };
    let transport = match integ.snee.transport {
        SneeTransport::All => "all",
        SneeTransport::Snee => "snee",
    };
    Some((technique, transport, integ.snee.rate))
}

/// Does `volpath_snee` run volpath's loop in `scene` (`Snee::forward_only`)?
fn forward_only(scene: &Scene) -> bool {
    matches!(&scene.integrator, Integrator::VolpathSnee(_, s) if s.forward_only)
}

/// Do camera beams run (`manifold/camera_beam.rs`: beams, a box-filtered pinhole in vacuum)?
fn camera_beams(scene: &Scene) -> bool {
    matches!(&scene.integrator, Integrator::VolpathSnee(_, s) if s.camera_beams && !s.forward_only)
}

/// Do beams run for some medium (`manifold/beam.rs`: `connection = complete`, `beams`, a
/// directional light, a smooth dielectric boundary)?
fn beams(scene: &Scene) -> bool {
    matches!(&scene.integrator, Integrator::VolpathSnee(_, s) if s.beams.iter().any(Option::is_some) && !s.forward_only)
}

/// Does emitter splitting at smooth dielectric vertices run (`manifold/split.rs`)?
fn split_glints(scene: &Scene) -> bool {
    matches!(&scene.integrator, Integrator::VolpathSnee(_, s) if s.split.is_some() && !s.forward_only)
}

pub fn summary(parsed: &ParsedScene, scene: &Scene) -> Summary {
    let film = &scene.film;
    let sampler = &scene.sampler;
    let sampler_kind = match sampler.kind {
        SamplerKind::Independent => "independent",
        SamplerKind::Stratified => "stratified, rendered as independent",
        SamplerKind::Multijitter => "multijitter, rendered as independent",
    };
    let pixel_format = match film.pixel_format {
        PixelFormat::Rgb => "rgb",
        PixelFormat::Rgba => "rgba",
    };
    let media: Vec<Json> = scene
        .media
        .iter()
        .map(|m| {
            let phase = match m.phase {
                Phase::Isotropic => json!({"type": "isotropic"}),
                Phase::Hg { g } => json!({"type": "hg", "g": g}),
            };
            json!({"id": m.id, "type": "homogeneous", "sigma_t": m.sigma_t.to_array(), "albedo": m.albedo.to_array(), "phase": phase})
        })
        .collect();
    let emitters: Vec<Json> = scene.emitters.iter().map(|e| json!(emitter_name(e))).collect();
    let b = scene.bounds;
    let bounds = if b.is_empty() { Json::Null } else { json!({"min": b.min.to_array(), "max": b.max.to_array()}) };
    let integ = &scene.integrator;
    let mut integ_json = json!({
        "type": integrator_name(integ.kind),
        "max_depth": integ.max_depth,
        "rr_depth": integ.rr_depth,
        "hide_emitters": integ.hide_emitters,
        "moment": integ.moment,
    });
    if let Some((technique, transport, rate)) = snee_params(integ) {
        integ_json["snee"] = json!(technique);
        integ_json["transport"] = json!(transport);
        integ_json["snee_rate"] = json!(rate);
        // Which estimator runs (the paper's, or the complete one with manifold NEE).
        integ_json["connection"] = json!(integ.connection.name());
        integ_json["reflection_chains"] = json!(integ.snee.chains);
        integ_json["forward_only"] = json!(forward_only(scene));
        integ_json["split_glints"] = json!(split_glints(scene));
        integ_json["beams"] = json!(beams(scene));
        integ_json["camera_beams"] = json!(camera_beams(scene));
    }
    let json = json!({
        "plugins": tree_json(&parsed.root, None),
        "shapes": scene.shapes.len(),
        "triangles": scene.triangle_count(),
        "bounds": bounds,
        "media": media,
        "emitters": emitters,
        "film": {"type": "hdrfilm", "width": film.width, "height": film.height, "pixel_format": pixel_format,
                 "crop_offset": [film.crop_offset.0, film.crop_offset.1], "crop_size": [film.crop_size.0, film.crop_size.1]},
        "spp": sampler.sample_count,
        "sampler": sampler_name(sampler.kind),
        "rendered_as": "independent",
        "integrator": integ_json,
    });

    let mut text = String::new();
    tree_text(&parsed.root, None, 0, &mut text);
    let _ = writeln!(text, "shapes: {}, triangles: {}", scene.shapes.len(), scene.triangle_count());
    if b.is_empty() {
        let _ = writeln!(text, "bounds: empty");
    } else {
        let p = |v: [f32; 3]| format!("({}, {}, {})", coord(v[0]), coord(v[1]), coord(v[2]));
        let _ = writeln!(text, "bounds: {} to {}", p(b.min.to_array()), p(b.max.to_array()));
    }
    let _ = writeln!(text, "media: {}", scene.media.len());
    for m in &scene.media {
        let _ = writeln!(text, "  {}", medium_text(m));
    }
    let names: Vec<&str> = scene.emitters.iter().map(emitter_name).collect();
    let _ = writeln!(text, "emitters: {} [{}]", names.len(), names.join(", "));
    let _ = writeln!(
        text,
        "film: {}x{} hdrfilm, {}, rfilter {} (crop {}x{} at {}, {})",
        film.width,
        film.height,
        pixel_format,
        rfilter_text(&film.filter),
        film.crop_size.0,
        film.crop_size.1,
        film.crop_offset.0,
        film.crop_offset.1
    );
    let _ = writeln!(text, "spp: {} ({})", sampler.sample_count, sampler_kind);
    let _ = write!(
        text,
        "integrator: {}, max_depth = {}, rr_depth = {}, hide_emitters = {}",
        integrator_name(integ.kind),
        depth_text(integ.max_depth),
        integ.rr_depth,
        integ.hide_emitters
    );
    if let Some((technique, transport, rate)) = snee_params(integ) {
        let rate = rate.map_or_else(|| "per medium (default)".to_string(), num);
        let _ = write!(text, ", snee = {technique}, transport = {transport}, snee_rate = {rate}");
        let _ = write!(text, ", connection = {}", integ.connection.name());
        if forward_only(scene) {
            let _ = write!(text, " (nothing of it applies here: renders with volpath's loop)");
        } else {
            if split_glints(scene) {
                let _ = write!(text, ", emitter splitting at smooth dielectric vertices");
            }
            if beams(scene) {
                let _ = write!(text, ", beams (light-traced internal reflections)");
            }
            if camera_beams(scene) {
                let _ = write!(text, ", camera beams (beam points splatted through one refraction)");
            }
        }
    }
    let _ = writeln!(text, "{}", if integ.moment { " (inside moment: also m2.R, m2.G, m2.B)" } else { "" });
    Summary { json, text }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_colours_read_as_in_xml() {
        assert_eq!(num(2.5), "2.5");
        assert_eq!(num(0.8), "0.8");
        assert_eq!(num(64.0), "64");
        assert_eq!(num(-4.0), "-4");
        assert_eq!(num(1.2999), "1.2999");
        assert_eq!(num(0.0), "0");
        assert_eq!(color_text(Spectrum::splat(0.8)), "0.8");
        assert_eq!(color_text(Spectrum::new(0.9, 0.8, 0.7)), "(0.9, 0.8, 0.7)");
        assert_eq!(phase_text(&Phase::Hg { g: 0.7 }), "hg (g = 0.7)");
        assert_eq!(depth_text(-1), "unbounded");
        assert_eq!(coord(-2.4e-16), "0");
        assert_eq!(coord(1.29999), "1.3");
        assert_eq!(coord(-4.0), "-4");
    }
}
