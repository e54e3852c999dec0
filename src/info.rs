//! `snee info`: a scene summary (plugins as a tree, triangle count, bounds, media, emitters,
//! film and samples), as text or JSON.

use crate::emitter::Emitter;
use crate::medium::Phase;
use crate::scene::desc::{ObjectDesc, Value};
use crate::scene::world::{Scene, SceneEmitter};
use crate::scene::xml::ParsedScene;
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

fn tree_json(obj: &ObjectDesc) -> Json {
    let children: Vec<Json> = obj
        .props
        .items()
        .iter()
        .filter_map(|p| match &p.value {
            Value::Object(o) => Some(tree_json(o)),
            _ => None,
        })
        .collect();
    json!({ "kind": obj.kind.tag(), "type": obj.plugin, "id": obj.id, "children": children })
}

fn tree_text(obj: &ObjectDesc, depth: usize, out: &mut String) {
    let id = obj.id.as_ref().map(|i| format!(" id=\"{}\"", i)).unwrap_or_default();
    let _ = writeln!(out, "{}{} {}{}", "  ".repeat(depth), obj.kind.tag(), obj.plugin, id);
    for p in obj.props.items() {
        if let Value::Object(o) = &p.value {
            tree_text(o, depth + 1, out);
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

pub fn summary(parsed: &ParsedScene, scene: &Scene) -> Summary {
    let film = &scene.film;
    let sampler = &scene.sampler;
    let sampler_kind = match sampler.kind {
        SamplerKind::Independent => "independent",
        SamplerKind::Stratified => "stratified (rendered as independent)",
        SamplerKind::Multijitter => "multijitter (rendered as independent)",
    };
    let media: Vec<Json> = scene
        .media
        .iter()
        .map(|m| {
            let phase = match m.phase {
                Phase::Isotropic => json!({"type": "isotropic"}),
                Phase::Hg { g } => json!({"type": "hg", "g": g}),
            };
            json!({"id": m.id, "sigma_t": m.sigma_t.to_array(), "albedo": m.albedo.to_array(), "phase": phase})
        })
        .collect();
    let emitters: Vec<Json> = scene.emitters.iter().map(|e| json!(emitter_name(e))).collect();
    let b = scene.bounds;
    let bounds = if b.is_empty() { Json::Null } else { json!({"min": b.min.to_array(), "max": b.max.to_array()}) };
    let integ = &scene.integrator;
    // volpath_snee: which estimator runs (the paper's, or the complete one with manifold NEE).
    let connection = (integ.kind == crate::integrator::IntegratorKind::VolpathSnee).then(|| integ.connection.name());
    let json = json!({
        "plugins": tree_json(&parsed.root),
        "shapes": scene.shapes.len(),
        "triangles": scene.triangle_count(),
        "bounds": bounds,
        "media": media,
        "emitters": emitters,
        "film": {"width": film.width, "height": film.height, "crop_offset": [film.crop_offset.0, film.crop_offset.1], "crop_size": [film.crop_size.0, film.crop_size.1]},
        "spp": sampler.sample_count,
        "sampler": sampler_kind,
        "integrator": {"type": format!("{:?}", integ.kind), "max_depth": integ.max_depth, "rr_depth": integ.rr_depth, "hide_emitters": integ.hide_emitters, "moment": integ.moment, "connection": connection},
    });
    let mut text = String::new();
    tree_text(&parsed.root, 0, &mut text);
    let _ = writeln!(text, "shapes: {}, triangles: {}", scene.shapes.len(), scene.triangle_count());
    if b.is_empty() {
        let _ = writeln!(text, "bounds: empty");
    } else {
        let _ = writeln!(
            text,
            "bounds: [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}]",
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
        );
    }
    let _ = writeln!(text, "media: {}", scene.media.len());
    for m in &scene.media {
        let _ = writeln!(
            text,
            "  {:?} sigma_t={:?} albedo={:?} phase={:?}",
            m.id,
            m.sigma_t.to_array(),
            m.albedo.to_array(),
            m.phase
        );
    }
    let names: Vec<&str> = scene.emitters.iter().map(emitter_name).collect();
    let _ = writeln!(text, "emitters: {} [{}]", names.len(), names.join(", "));
    let _ = writeln!(
        text,
        "film: {}x{} (crop {}x{} at {},{})",
        film.width, film.height, film.crop_size.0, film.crop_size.1, film.crop_offset.0, film.crop_offset.1
    );
    let _ = writeln!(text, "spp: {} ({})", sampler.sample_count, sampler_kind);
    let _ = writeln!(
        text,
        "integrator: {:?} max_depth={} rr_depth={}{}{}",
        integ.kind,
        integ.max_depth,
        integ.rr_depth,
        if integ.moment { " (moment)" } else { "" },
        connection.map_or(String::new(), |c| format!(" connection={c}"))
    );
    Summary { json, text }
}
