//! The scene description: a typed tree of plugin objects with their properties, as Mitsuba's
//! parser produces it after `$param` substitution, `<default>`, `<include>` and `<ref>` resolution.
//!
//! Plugin constructors read their parameters through [`Props`], which records what was read so
//! that [`Props::finish`] can report every unknown or unused parameter at its source position,
//! listing the parameters the plugin does accept.

use super::error::{Error, Result, SrcPos};
use crate::color::{Spectrum, UNIFORM_EMITTER_TINT};
use glam::{DMat4, DVec3, Mat4, Vec3};
use std::cell::{Cell, RefCell};
use std::rc::Rc;

/// The kind of a plugin object: the XML tag that declared it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PluginKind {
    Scene,
    Integrator,
    Sensor,
    Film,
    RFilter,
    Sampler,
    Shape,
    Bsdf,
    Texture,
    Medium,
    Phase,
    Emitter,
}

impl PluginKind {
    /// The XML tag of this kind (`"bsdf"`, `"rfilter"`, ...).
    pub fn tag(self) -> &'static str {
        match self {
            PluginKind::Scene => "scene",
            PluginKind::Integrator => "integrator",
            PluginKind::Sensor => "sensor",
            PluginKind::Film => "film",
            PluginKind::RFilter => "rfilter",
            PluginKind::Sampler => "sampler",
            PluginKind::Shape => "shape",
            PluginKind::Bsdf => "bsdf",
            PluginKind::Texture => "texture",
            PluginKind::Medium => "medium",
            PluginKind::Phase => "phase",
            PluginKind::Emitter => "emitter",
        }
    }
    /// The kind for an XML tag; `None` for tags that are not plugin objects.
    pub fn from_tag(tag: &str) -> Option<PluginKind> {
        Some(match tag {
            "scene" => PluginKind::Scene,
            "integrator" => PluginKind::Integrator,
            "sensor" => PluginKind::Sensor,
            "film" => PluginKind::Film,
            "rfilter" => PluginKind::RFilter,
            "sampler" => PluginKind::Sampler,
            "shape" => PluginKind::Shape,
            "bsdf" => PluginKind::Bsdf,
            "texture" => PluginKind::Texture,
            "medium" => PluginKind::Medium,
            "phase" => PluginKind::Phase,
            "emitter" => PluginKind::Emitter,
            _ => return None,
        })
    }
}

/// One plugin object: `<bsdf type="roughdielectric" id="glass"> ... </bsdf>`.
#[derive(Debug)]
pub struct ObjectDesc {
    pub kind: PluginKind,
    /// The `type` attribute (`"roughdielectric"`); `"scene"` for the root.
    pub plugin: String,
    pub id: Option<String>,
    /// Position of the opening tag.
    pub pos: SrcPos,
    pub props: Props,
}

/// A spectrum given with `<spectrum>`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpectrumValue {
    /// `<spectrum value="0.5"/>`.
    Uniform(f64),
    /// A `wavelength:value` list, already converted to linear sRGB (CIE 1931).
    Rgb(DVec3),
}

/// A property value.
#[derive(Clone, Debug)]
pub enum Value {
    Float(f64),
    Integer(i64),
    Bool(bool),
    String(String),
    Point(DVec3),
    Vector(DVec3),
    Rgb(DVec3),
    Spectrum(SpectrumValue),
    /// Composed `to_world`-style matrix (column vectors, as glam: `M * p`).
    Transform(DMat4),
    /// A nested object or a resolved `<ref>` (shared when referenced twice).
    Object(Rc<ObjectDesc>),
}

impl Value {
    /// The XML tag that produces this kind of value, for error messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Float(_) => "float",
            Value::Integer(_) => "integer",
            Value::Bool(_) => "boolean",
            Value::String(_) => "string",
            Value::Point(_) => "point",
            Value::Vector(_) => "vector",
            Value::Rgb(_) => "rgb",
            Value::Spectrum(_) => "spectrum",
            Value::Transform(_) => "transform",
            Value::Object(o) => o.kind.tag(),
        }
    }
}

/// One named property with the position of the tag that set it.
#[derive(Debug)]
pub struct Prop {
    /// The `name` attribute; nested objects without one get `_arg_N` as in Mitsuba.
    pub name: String,
    pub value: Value,
    pub pos: SrcPos,
    used: Cell<bool>,
}

/// The properties of one object, in document order, with use tracking.
#[derive(Debug)]
pub struct Props {
    pub owner_kind: PluginKind,
    pub owner_plugin: String,
    pub owner_pos: SrcPos,
    items: Vec<Prop>,
    queried: RefCell<Vec<String>>,
}

/// A reflectance-like parameter: a constant colour or a nested texture object.
#[derive(Clone, Debug)]
pub enum TexArg {
    Const(Spectrum),
    Texture(Rc<ObjectDesc>),
}

impl Props {
    pub fn new(owner_kind: PluginKind, owner_plugin: &str, owner_pos: SrcPos) -> Props {
        Props {
            owner_kind,
            owner_plugin: owner_plugin.to_string(),
            owner_pos,
            items: Vec::new(),
            queried: RefCell::new(Vec::new()),
        }
    }

    /// Add a property. A second property with the same name is an error (as in Mitsuba).
    pub fn push(&mut self, name: &str, value: Value, pos: SrcPos) -> Result<()> {
        if let Some(p) = self.items.iter().find(|p| p.name == name) {
            return Err(Error::at(
                &pos,
                format!("property \"{}\" was already specified at {} for {}", name, p.pos, self.describe_owner()),
            ));
        }
        self.items.push(Prop { name: name.to_string(), value, pos, used: Cell::new(false) });
        Ok(())
    }

    /// Push a nested object under an automatic name (`_arg_N`) when it has none.
    pub fn push_object(&mut self, name: Option<&str>, obj: Rc<ObjectDesc>, pos: SrcPos) -> Result<()> {
        let auto;
        let n = match name {
            Some(n) => n,
            None => {
                auto = format!("_arg_{}", self.items.len());
                &auto
            }
        };
        self.push(n, Value::Object(obj), pos)
    }

    /// All properties in document order (no use tracking).
    pub fn items(&self) -> &[Prop] {
        &self.items
    }

    pub fn describe_owner(&self) -> String {
        format!("{} \"{}\"", self.owner_kind.tag(), self.owner_plugin)
    }

    fn note(&self, name: &str) {
        let mut q = self.queried.borrow_mut();
        if !q.iter().any(|n| n == name) {
            q.push(name.to_string());
        }
    }

    /// Look a property up by name, marking it used.
    pub fn get(&self, name: &str) -> Option<&Prop> {
        self.note(name);
        let p = self.items.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// True when the property is present (does not mark it used).
    pub fn has(&self, name: &str) -> bool {
        self.note(name);
        self.items.iter().any(|p| p.name == name)
    }

    /// Source position of a property, or of the owning object when absent.
    pub fn pos_of(&self, name: &str) -> SrcPos {
        self.items.iter().find(|p| p.name == name).map(|p| p.pos.clone()).unwrap_or_else(|| self.owner_pos.clone())
    }

    /// An error positioned at a property (or at the object when the property is absent).
    pub fn error(&self, name: &str, msg: impl Into<String>) -> Error {
        Error::at(&self.pos_of(name), msg)
    }

    fn type_error(&self, p: &Prop, expected: &str) -> Error {
        Error::at(
            &p.pos,
            format!(
                "property \"{}\" of {} has type {}, expected {}",
                p.name,
                self.describe_owner(),
                p.value.type_name(),
                expected
            ),
        )
    }

    pub fn float_opt(&self, name: &str) -> Result<Option<f32>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Float(v) => Ok(Some(*v as f32)),
                Value::Integer(v) => Ok(Some(*v as f32)),
                _ => Err(self.type_error(p, "float")),
            },
        }
    }
    pub fn float(&self, name: &str, default: f32) -> Result<f32> {
        Ok(self.float_opt(name)?.unwrap_or(default))
    }
    pub fn float_req(&self, name: &str) -> Result<f32> {
        self.float_opt(name)?.ok_or_else(|| self.missing(name, "float"))
    }

    pub fn int_opt(&self, name: &str) -> Result<Option<i64>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Integer(v) => Ok(Some(*v)),
                _ => Err(self.type_error(p, "integer")),
            },
        }
    }
    pub fn int(&self, name: &str, default: i64) -> Result<i64> {
        Ok(self.int_opt(name)?.unwrap_or(default))
    }

    pub fn bool_opt(&self, name: &str) -> Result<Option<bool>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Bool(v) => Ok(Some(*v)),
                _ => Err(self.type_error(p, "boolean")),
            },
        }
    }
    pub fn bool(&self, name: &str, default: bool) -> Result<bool> {
        Ok(self.bool_opt(name)?.unwrap_or(default))
    }

    pub fn string_opt(&self, name: &str) -> Result<Option<String>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::String(v) => Ok(Some(v.clone())),
                _ => Err(self.type_error(p, "string")),
            },
        }
    }
    pub fn string(&self, name: &str, default: &str) -> Result<String> {
        Ok(self.string_opt(name)?.unwrap_or_else(|| default.to_string()))
    }

    /// A `<point>` (a `<vector>` is accepted too, as Mitsuba's properties are both 3-vectors).
    pub fn point_opt(&self, name: &str) -> Result<Option<Vec3>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Point(v) | Value::Vector(v) => Ok(Some(v.as_vec3())),
                _ => Err(self.type_error(p, "point")),
            },
        }
    }
    pub fn point(&self, name: &str, default: Vec3) -> Result<Vec3> {
        Ok(self.point_opt(name)?.unwrap_or(default))
    }
    pub fn vector_opt(&self, name: &str) -> Result<Option<Vec3>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Point(v) | Value::Vector(v) => Ok(Some(v.as_vec3())),
                _ => Err(self.type_error(p, "vector")),
            },
        }
    }
    pub fn vector(&self, name: &str, default: Vec3) -> Result<Vec3> {
        Ok(self.vector_opt(name)?.unwrap_or(default))
    }

    pub fn transform_opt(&self, name: &str) -> Result<Option<DMat4>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Transform(m) => Ok(Some(*m)),
                _ => Err(self.type_error(p, "transform")),
            },
        }
    }
    /// A transform in single precision, identity when absent.
    pub fn transform(&self, name: &str) -> Result<Mat4> {
        Ok(self.transform_opt(name)?.map(|m| m.as_mat4()).unwrap_or(Mat4::IDENTITY))
    }

    /// A colour: `<float>`, `<integer>`, `<rgb>` or `<spectrum>`. RGB values outside [0, 1] are an error
    /// except on emitters; a uniform `<spectrum>` on an emitter is tinted as Mitsuba does in RGB mode.
    pub fn color_opt(&self, name: &str) -> Result<Option<Spectrum>> {
        let Some(p) = self.get(name) else { return Ok(None) };
        let emitter = self.owner_kind == PluginKind::Emitter;
        let c = match &p.value {
            Value::Float(v) => Vec3::splat(*v as f32),
            Value::Integer(v) => Vec3::splat(*v as f32),
            Value::Rgb(v) => {
                if !emitter && (v.min_element() < 0.0 || v.max_element() > 1.0) {
                    return Err(Error::at(
                        &p.pos,
                        format!(
                            "rgb value ({}, {}, {}) of \"{}\" is outside [0, 1]; only emitters accept that (put the magnitude in a scale parameter)",
                            v.x, v.y, v.z, p.name
                        ),
                    ));
                }
                v.as_vec3()
            }
            Value::Spectrum(SpectrumValue::Uniform(v)) => {
                if emitter {
                    UNIFORM_EMITTER_TINT * (*v as f32)
                } else {
                    Vec3::splat(*v as f32)
                }
            }
            Value::Spectrum(SpectrumValue::Rgb(v)) => v.as_vec3(),
            _ => return Err(self.type_error(p, "float, rgb or spectrum")),
        };
        if !(c.x.is_finite() && c.y.is_finite() && c.z.is_finite()) {
            return Err(Error::at(&p.pos, format!("\"{}\" is not finite", p.name)));
        }
        // Found by fuzzing: emission near f32::MAX gives finite samples whose pixel sums overflow.
        if emitter && c.abs().max_element() > MAX_EMISSION {
            return Err(Error::at(
                &p.pos,
                format!("\"{}\" is beyond {MAX_EMISSION:e}, where pixel sums overflow", p.name),
            ));
        }
        Ok(Some(c))
    }
    pub fn color(&self, name: &str, default: Spectrum) -> Result<Spectrum> {
        Ok(self.color_opt(name)?.unwrap_or(default))
    }

    /// A colour or a nested `<texture>` (for reflectance-like parameters).
    pub fn texture_opt(&self, name: &str) -> Result<Option<TexArg>> {
        if let Some(p) = self.items.iter().find(|p| p.name == name) {
            if let Value::Object(o) = &p.value {
                self.get(name);
                if o.kind != PluginKind::Texture {
                    return Err(self.type_error(p, "texture or colour"));
                }
                return Ok(Some(TexArg::Texture(o.clone())));
            }
        }
        Ok(self.color_opt(name)?.map(TexArg::Const))
    }
    pub fn texture(&self, name: &str, default: Spectrum) -> Result<TexArg> {
        Ok(self.texture_opt(name)?.unwrap_or(TexArg::Const(default)))
    }

    /// An index of refraction: a float or a named material ("bk7", "water", ...).
    pub fn ior(&self, name: &str, default: &str) -> Result<f32> {
        let Some(p) = self.get(name) else {
            return Ok(lookup_ior(default).expect("default IOR name is in the table"));
        };
        match &p.value {
            Value::Float(v) => Ok(*v as f32),
            Value::Integer(v) => Ok(*v as f32),
            Value::String(s) => lookup_ior(s).ok_or_else(|| {
                let names: Vec<&str> = IOR_TABLE.iter().map(|(n, _)| *n).collect();
                Error::at(
                    &p.pos,
                    format!("unknown IOR name \"{}\" (expected a number or one of: {})", s, names.join(", ")),
                )
            }),
            _ => Err(self.type_error(p, "float or IOR name")),
        }
    }

    /// Nested objects (in document order), marking them used. Each item: (property name, object).
    pub fn objects(&self) -> Vec<(String, Rc<ObjectDesc>)> {
        let mut out = Vec::new();
        for p in &self.items {
            if let Value::Object(o) = &p.value {
                p.used.set(true);
                out.push((p.name.clone(), o.clone()));
            }
        }
        out
    }

    /// Nested objects of one kind, marking them used.
    pub fn objects_of(&self, kind: PluginKind) -> Vec<(String, Rc<ObjectDesc>)> {
        let mut out = Vec::new();
        for p in &self.items {
            if let Value::Object(o) = &p.value {
                if o.kind == kind {
                    p.used.set(true);
                    out.push((p.name.clone(), o.clone()));
                }
            }
        }
        out
    }

    /// At most one nested object of a kind; a second one is an error at its position.
    pub fn object_of(&self, kind: PluginKind) -> Result<Option<Rc<ObjectDesc>>> {
        let all = self.objects_of(kind);
        if all.len() > 1 {
            return Err(Error::at(
                &all[1].1.pos,
                format!("{} accepts only one nested {}", self.describe_owner(), kind.tag()),
            ));
        }
        Ok(all.into_iter().next().map(|(_, o)| o))
    }

    /// A named nested object (e.g. `interior`), checking its kind.
    pub fn object_named(&self, name: &str, kind: PluginKind) -> Result<Option<Rc<ObjectDesc>>> {
        let Some(p) = self.get(name) else { return Ok(None) };
        match &p.value {
            Value::Object(o) if o.kind == kind => Ok(Some(o.clone())),
            _ => Err(self.type_error(p, kind.tag())),
        }
    }

    fn missing(&self, name: &str, ty: &str) -> Error {
        Error::at(&self.owner_pos, format!("{} requires the {} property \"{}\"", self.describe_owner(), ty, name))
    }

    /// Error on the first property nobody read: an unknown parameter or a nested object the plugin
    /// does not take. Call after the plugin has read everything it accepts.
    pub fn finish(&self) -> Result<()> {
        for p in &self.items {
            if p.used.get() {
                continue;
            }
            let q = self.queried.borrow();
            let expected = if q.is_empty() { "none".to_string() } else { q.join(", ") };
            return Err(match &p.value {
                Value::Object(o) => Error::at(
                    &p.pos,
                    format!("{} does not accept a nested {} \"{}\"", self.describe_owner(), o.kind.tag(), o.plugin),
                ),
                _ => Error::at(
                    &p.pos,
                    format!(
                        "unknown or unused parameter \"{}\" for {} (expected one of: {})",
                        p.name,
                        self.describe_owner(),
                        expected
                    ),
                ),
            });
        }
        Ok(())
    }
}

/// Mitsuba's table of named indices of refraction (`ior.h`).
/// Largest emitted value accepted (radiance, intensity, irradiance, envmap scale × pixel): beyond
/// it, sums of a few samples × filter weights overflow f32 (found by fuzzing).
pub const MAX_EMISSION: f32 = 1e30;

pub const IOR_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

pub fn lookup_ior(name: &str) -> Option<f32> {
    let lower = name.to_ascii_lowercase();
    IOR_TABLE.iter().find(|(n, _)| *n == lower).map(|(_, v)| *v)
}
