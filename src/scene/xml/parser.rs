//! Stage 2 of parsing: element trees (main file and `<include>`d files) → a flat list of object
//! nodes, following Mitsuba 3.9's `parse_xml_node` tag by tag. References stay unresolved here
//! (a `<ref>` may name an object defined later); [`super::build`] resolves them.

use super::dom::{self, check_attrs, find, Attr, Element};
use super::number::{parse_bool, parse_float, parse_int, parse_version, tokens, Version};
use super::params::Params;
use super::spectrum::{parse_spectrum, spectrum_list_to_srgb, SpectrumSpec};
use super::transform;
use crate::scene::desc::{PluginKind, SpectrumValue, Value};
use crate::scene::error::{Error, Result, SrcPos};
use crate::scene::resolver::FileResolver;
use glam::{DMat4, DVec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Mitsuba's `ParserConfig::max_include_depth`.
pub const MAX_INCLUDE_DEPTH: usize = 15;

/// The tags that declare plugin objects (besides the root `<scene>`).
const OBJECT_TAGS: &[&str] =
    &["integrator", "sensor", "film", "rfilter", "sampler", "shape", "bsdf", "texture", "medium", "phase", "emitter"];
/// Every other tag.
const OTHER_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "point",
    "vector",
    "rgb",
    "spectrum",
    "transform",
    "ref",
    "include",
    "alias",
    "default",
    "path",
];

/// A property value before reference resolution.
#[derive(Clone, Debug)]
pub enum NValue {
    Value(Value),
    /// A nested object: index into [`Parser::nodes`].
    Node(usize),
    /// `<ref id="..."/>`, resolved later.
    Ref(String),
}

#[derive(Clone, Debug)]
pub struct NProp {
    pub name: String,
    pub value: NValue,
    pub pos: SrcPos,
}

/// One plugin object before reference resolution.
#[derive(Clone, Debug)]
pub struct Node {
    pub kind: PluginKind,
    pub plugin: String,
    pub id: Option<String>,
    pub pos: SrcPos,
    /// Version of the file the object was written in (decides the upgrade of old scenes).
    pub version: Version,
    pub props: Vec<NProp>,
    /// Mitsuba's per-object counter for `_arg_N` names.
    arg_counter: usize,
}

impl Node {
    fn new(kind: PluginKind, plugin: &str, id: Option<String>, pos: SrcPos, version: Version) -> Node {
        Node { kind, plugin: plugin.to_string(), id, pos, version, props: Vec::new(), arg_counter: 0 }
    }

    pub fn describe(&self) -> String {
        format!("{} \"{}\"", self.kind.tag(), self.plugin)
    }
}

/// Per-file parsing context.
struct FileCtx {
    version: Version,
    /// Search folders for `<include>` and `<path>` (this file's folder first).
    resolver: FileResolver,
    /// Node that receives this file's top-level children.
    root: usize,
    /// Include nesting depth (0 for the main file).
    depth: usize,
}

/// The parser state shared by the main file and everything it includes.
pub struct Parser {
    pub nodes: Vec<Node>,
    /// `id` → node (aliases included), with the position of the definition.
    pub ids: HashMap<String, (usize, SrcPos)>,
    pub params: Params,
    /// Canonical paths of the files being parsed (main file first), for include cycles.
    include_stack: Vec<PathBuf>,
    /// Current element nesting, counted across included files.
    depth: usize,
}

/// The value of an attribute that [`check_attrs`] has made sure exists.
fn req<'a>(attrs: &'a [Attr], name: &str, pos: &SrcPos) -> Result<&'a Attr> {
    find(attrs, name).ok_or_else(|| Error::at(pos, format!("missing required attribute \"{name}\"")))
}

impl Parser {
    pub fn new(params: Params) -> Parser {
        Parser { nodes: Vec::new(), ids: HashMap::new(), params, include_stack: Vec::new(), depth: 0 }
    }

    /// Parse the main scene document. `resolver` searches the scene's folder; it comes back with
    /// the `<path>` folders prepended. Returns the root node index (always 0).
    pub fn parse_main(
        &mut self,
        text: &str,
        file: Arc<str>,
        canonical: PathBuf,
        resolver: &mut FileResolver,
    ) -> Result<usize> {
        let root_el = dom::parse_document(text, &file)?;
        let version = root_version(&root_el)?;
        if root_el.name != "scene" {
            return Err(Error::at(
                &root_el.pos,
                format!("the root element must be <scene version=\"...\">, found <{}>", root_el.name),
            ));
        }
        let attrs = self.substitute_all(&root_el)?;
        check_attrs("scene", &root_el.pos, &attrs, &["version", "type", "id", "name"], &["version"])?;
        check_scene_type(&attrs)?;
        let root = self.nodes.len();
        self.nodes.push(Node::new(PluginKind::Scene, "scene", None, root_el.pos.clone(), version));
        self.include_stack.push(canonical);
        let mut ctx = FileCtx { version, resolver: resolver.clone(), root, depth: 0 };
        for child in &root_el.children {
            self.element(&mut ctx, child, root)?;
        }
        self.include_stack.pop();
        *resolver = ctx.resolver;
        Ok(root)
    }

    /// `$param` substitution of every attribute of an element, in order.
    fn substitute_all(&mut self, el: &Element) -> Result<Vec<Attr>> {
        el.attrs
            .iter()
            .map(|a| match self.params.substitute(&a.value) {
                Ok(value) => Ok(Attr { name: a.name.clone(), value, pos: a.pos.clone() }),
                Err(name) => Err(Error::at(
                    &a.pos,
                    format!(
                        "undefined parameter ${name} in attribute \"{}\" (define it with <default name=\"{name}\" value=\"...\"/> before this line or -D {name}=...; write \\$ for a literal $)",
                        a.name
                    ),
                )),
            })
            .collect()
    }

    /// Add a property to a node; a second property of the same name is an error.
    fn push_prop(&mut self, node: usize, name: String, value: NValue, pos: SrcPos) -> Result<()> {
        let Some(n) = self.nodes.get_mut(node) else { return Err(Error::at(&pos, "internal error: no parent object")) };
        if let Some(prev) = n.props.iter().find(|p| p.name == name) {
            return Err(Error::at(
                &pos,
                format!("property \"{name}\" was already specified at {} for {}", prev.pos, n.describe()),
            ));
        }
        n.props.push(NProp { name, value, pos });
        Ok(())
    }

    /// The `name` attribute, or the parent's next `_arg_N`.
    fn prop_name(&mut self, parent: usize, attrs: &[Attr]) -> String {
        match find(attrs, "name") {
            Some(a) if !a.value.is_empty() => a.value.clone(),
            _ => {
                let Some(p) = self.nodes.get_mut(parent) else { return "_arg_0".into() };
                let n = p.arg_counter;
                p.arg_counter += 1;
                format!("_arg_{n}")
            }
        }
    }

    fn register_id(&mut self, id: &str, node: usize, pos: &SrcPos) -> Result<()> {
        if let Some((_, prev)) = self.ids.get(id) {
            return Err(Error::at(pos, format!("duplicate id \"{id}\" (first defined at {prev})")));
        }
        self.ids.insert(id.to_string(), (node, pos.clone()));
        Ok(())
    }

    /// One element inside an object (or inside the root of a file).
    fn element(&mut self, ctx: &mut FileCtx, el: &Element, parent: usize) -> Result<()> {
        // Included files nest too: bound the total depth (and so the recursion).
        if self.depth >= dom::MAX_DEPTH {
            return Err(Error::at(
                &el.pos,
                format!("elements are nested more than {} levels deep (counting included files)", dom::MAX_DEPTH),
            ));
        }
        self.depth += 1;
        let r = self.element_inner(ctx, el, parent);
        self.depth -= 1;
        r
    }

    fn element_inner(&mut self, ctx: &mut FileCtx, el: &Element, parent: usize) -> Result<()> {
        let mut attrs = self.substitute_all(el)?;
        let tag = el.name.as_str();
        let pos = &el.pos;

        // <spectrum type="..."> is a spectrum plugin, i.e. a texture object.
        let kind = if tag == "spectrum" && find(&attrs, "type").is_some() {
            Some(PluginKind::Texture)
        } else {
            PluginKind::from_tag(tag)
        };
        if let Some(kind) = kind {
            if kind == PluginKind::Scene {
                return Err(Error::at(pos, "<scene> can only be the root element of a file"));
            }
            return self.object(ctx, el, &attrs, kind, parent);
        }

        match tag {
            "float" | "integer" | "boolean" | "string" | "rgb" => {
                check_attrs(tag, pos, &attrs, &["name", "value"], &["name", "value"])?;
                let name = req(&attrs, "name", pos)?.value.clone();
                let v = req(&attrs, "value", pos)?;
                let value = scalar_value(tag, v)?;
                self.push_prop(parent, name, NValue::Value(value), pos.clone())?;
            }
            "point" | "vector" => {
                transform::expand_value_to_xyz(tag, &mut attrs)?;
                check_attrs(tag, pos, &attrs, &["name", "x", "y", "z"], &["name", "x", "y", "z"])?;
                let name = req(&attrs, "name", pos)?.value.clone();
                let v = transform::parse_xyz(&attrs, 0.0)?;
                let value = if tag == "point" { Value::Point(v) } else { Value::Vector(v) };
                self.push_prop(parent, name, NValue::Value(value), pos.clone())?;
            }
            "spectrum" => {
                check_attrs(tag, pos, &attrs, &["name", "value", "filename"], &["name"])?;
                let name = req(&attrs, "name", pos)?.value.clone();
                let value = find(&attrs, "value").filter(|a| !a.value.is_empty());
                let filename = find(&attrs, "filename").filter(|a| !a.value.is_empty());
                let v = match (value, filename) {
                    (Some(v), None) => v,
                    (None, Some(f)) => {
                        return Err(Error::at(
                            &f.pos,
                            format!(
                                "<spectrum filename=\"{}\"> is not supported: give the values inline, e.g. value=\"400:0.1, 500:0.5, 600:0.8\"",
                                f.value
                            ),
                        ))
                    }
                    _ => {
                        return Err(Error::at(
                            pos,
                            "<spectrum> element requires either a \"value\" or a \"filename\" attribute (but not both)",
                        ))
                    }
                };
                let emitter = self.nodes.get(parent).is_some_and(|n| n.kind == PluginKind::Emitter);
                let spec = parse_spectrum(&v.value).map_err(|m| Error::at(&v.pos, m))?;
                let value = match spec {
                    SpectrumSpec::Uniform(u) => SpectrumValue::Uniform(u),
                    // Mitsuba's RGB mode: reflectance-like values are weighted by D65 and
                    // clamped to [0, 1]; emitter values are neither.
                    SpectrumSpec::List(w, s) => SpectrumValue::Rgb(spectrum_list_to_srgb(&w, &s, !emitter, !emitter)),
                };
                self.push_prop(parent, name, NValue::Value(Value::Spectrum(value)), pos.clone())?;
            }
            "transform" => {
                check_attrs(tag, pos, &attrs, &["name"], &["name"])?;
                let name = req(&attrs, "name", pos)?.value.clone();
                let mut m = DMat4::IDENTITY;
                for op in &el.children {
                    let mut op_attrs = self.substitute_all(op)?;
                    m = transform::apply_op(&op.name, &op.pos, &mut op_attrs, m)?;
                }
                self.push_prop(parent, name, NValue::Value(Value::Transform(m)), pos.clone())?;
                return Ok(());
            }
            "ref" => {
                check_attrs(tag, pos, &attrs, &["id", "name"], &["id"])?;
                let id = req(&attrs, "id", pos)?.value.clone();
                let name = self.prop_name(parent, &attrs);
                self.push_prop(parent, name, NValue::Ref(id), pos.clone())?;
            }
            "alias" => {
                check_attrs(tag, pos, &attrs, &["id", "as"], &["id", "as"])?;
                let src = req(&attrs, "id", pos)?;
                let dst = req(&attrs, "as", pos)?;
                if let Some((_, prev)) = self.ids.get(&dst.value) {
                    return Err(Error::at(
                        &dst.pos,
                        format!("alias destination id \"{}\" already exists (defined at {prev})", dst.value),
                    ));
                }
                let Some((node, _)) = self.ids.get(&src.value).cloned() else {
                    return Err(Error::at(
                        &src.pos,
                        format!("alias source id \"{}\" not found (it must be defined before the <alias>)", src.value),
                    ));
                };
                self.ids.insert(dst.value.clone(), (node, pos.clone()));
            }
            "default" => {
                check_attrs(tag, pos, &attrs, &["name", "value"], &["name", "value"])?;
                let name = req(&attrs, "name", pos)?;
                if name.value.is_empty() {
                    return Err(Error::at(&name.pos, "<default>: name must be non-empty"));
                }
                let value = req(&attrs, "value", pos)?.value.clone();
                let name = name.value.clone();
                self.params.add_default(&name, &value);
            }
            "path" => {
                check_attrs(tag, pos, &attrs, &["value"], &["value"])?;
                if parent != ctx.root {
                    return Err(Error::at(pos, "<path> can only be a direct child of the root <scene>"));
                }
                let v = req(&attrs, "value", pos)?;
                let folder = ctx.resolver.resolve(&v.value).ok_or_else(|| {
                    Error::at(
                        &v.pos,
                        format!("<path>: folder \"{}\" not found (searched: {})", v.value, searched(&ctx.resolver)),
                    )
                })?;
                ctx.resolver.prepend(folder);
            }
            "include" => {
                check_attrs(tag, pos, &attrs, &["filename", "name"], &["filename"])?;
                self.include(ctx, el, &attrs, parent)?;
            }
            "translate" | "rotate" | "scale" | "lookat" | "matrix" => {
                return Err(Error::at(pos, format!("<{tag}> can only appear inside a <transform>")));
            }
            _ => {
                let hint = if tag == "volume" || tag == "field" {
                    format!("<{tag}> objects are not supported by snee")
                } else {
                    format!("unknown element <{tag}>")
                };
                return Err(Error::at(
                    pos,
                    format!("{hint} (expected one of: {}, {})", OBJECT_TAGS.join(", "), OTHER_TAGS.join(", ")),
                ));
            }
        }
        // Properties and directives have no child elements.
        if let Some(child) = el.children.first() {
            return Err(Error::at(&child.pos, format!("<{}> cannot occur inside <{tag}>", child.name)));
        }
        Ok(())
    }

    /// A nested plugin object.
    fn object(
        &mut self,
        ctx: &mut FileCtx,
        el: &Element,
        attrs: &[Attr],
        kind: PluginKind,
        parent: usize,
    ) -> Result<()> {
        let pos = &el.pos;
        check_attrs(&el.name, pos, attrs, &["type", "id", "name"], &["type"])?;
        let plugin = req(attrs, "type", pos)?.value.clone();
        let id = find(attrs, "id").map(|a| a.value.clone()).filter(|v| !v.is_empty());
        let name = self.prop_name(parent, attrs);
        let idx = self.nodes.len();
        if let Some(id) = &id {
            self.register_id(id, idx, pos)?;
        }
        self.nodes.push(Node::new(kind, &plugin, id, pos.clone(), ctx.version));
        self.push_prop(parent, name, NValue::Node(idx), pos.clone())?;
        for child in &el.children {
            self.element(ctx, child, idx)?;
        }
        Ok(())
    }

    /// `<include filename="..." [name="..."]/>`: a file whose root `<scene>`'s objects join the
    /// parent here (its other properties are dropped, as in Mitsuba), or whose root object
    /// (e.g. `<bsdf version="3.0.0" type="...">`) becomes a nested object.
    fn include(&mut self, ctx: &mut FileCtx, el: &Element, attrs: &[Attr], parent: usize) -> Result<()> {
        let pos = &el.pos;
        let fname = req(attrs, "filename", pos)?;
        let path = ctx.resolver.resolve(&fname.value).ok_or_else(|| {
            Error::at(
                &fname.pos,
                format!("included file \"{}\" not found (searched: {})", fname.value, searched(&ctx.resolver)),
            )
        })?;
        if ctx.depth + 1 >= MAX_INCLUDE_DEPTH {
            return Err(Error::at(pos, format!("exceeded the maximum include depth of {MAX_INCLUDE_DEPTH}")));
        }
        let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
        if let Some(first) = self.include_stack.iter().position(|p| *p == canonical) {
            let chain: Vec<String> =
                self.include_stack[first..].iter().chain([&canonical]).map(|p| p.display().to_string()).collect();
            return Err(Error::at(pos, format!("include cycle: {}", chain.join(" includes "))));
        }
        let text = std::fs::read(&path)
            .map_err(|e| Error::at(&fname.pos, format!("could not read included file \"{}\": {e}", path.display())))?;
        let file: Arc<str> = Arc::from(path.display().to_string());
        let text = String::from_utf8(text).map_err(|e| {
            let ok = e.utf8_error().valid_up_to();
            let prefix = String::from_utf8_lossy(&e.as_bytes()[..ok]).into_owned();
            Error::at(&dom::LineIndex::new(&prefix, file.clone()).pos(ok), "the file is not valid UTF-8")
        });
        let context = |e: Error| Error { msg: format!("{}\n  (in the file included at {pos})", e.msg), pos: e.pos };
        let text = text.map_err(context)?;
        self.include_stack.push(canonical);
        let r = self.include_text(ctx, &text, file, &path, attrs, parent).map_err(context);
        self.include_stack.pop();
        r
    }

    fn include_text(
        &mut self,
        ctx: &mut FileCtx,
        text: &str,
        file: Arc<str>,
        path: &Path,
        include_attrs: &[Attr],
        parent: usize,
    ) -> Result<()> {
        let root_el = dom::parse_document(text, &file)?;
        let version = root_version(&root_el)?;
        let mut resolver = ctx.resolver.clone();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            resolver.prepend(dir.to_path_buf());
        }
        let attrs = self.substitute_all(&root_el)?;
        let is_scene = root_el.name == "scene";
        let kind = if root_el.name == "spectrum" && find(&attrs, "type").is_some() {
            Some(PluginKind::Texture)
        } else {
            PluginKind::from_tag(&root_el.name)
        };
        let Some(kind) = kind else {
            return Err(Error::at(
                &root_el.pos,
                format!("the root element of an included file must be <scene> or an object, found <{}>", root_el.name),
            ));
        };
        if is_scene {
            check_attrs("scene", &root_el.pos, &attrs, &["version", "type", "id", "name"], &["version"])?;
            check_scene_type(&attrs)?;
            // A scratch node collects the file's top-level children; its objects then move to
            // the parent (unnamed ones renumbered with the parent's counter).
            let scratch = self.nodes.len();
            self.nodes.push(Node::new(PluginKind::Scene, "scene", None, root_el.pos.clone(), version));
            let mut sub = FileCtx { version, resolver, root: scratch, depth: ctx.depth + 1 };
            for child in &root_el.children {
                self.element(&mut sub, child, scratch)?;
            }
            let props = self.nodes.get_mut(scratch).map(|n| std::mem::take(&mut n.props)).unwrap_or_default();
            for p in props {
                // Mitsuba keeps only the nested objects of an included scene.
                if let NValue::Node(_) = p.value {
                    let name = if p.name.starts_with("_arg_") { self.prop_name(parent, &[]) } else { p.name };
                    self.push_prop(parent, name, p.value, p.pos)?;
                }
            }
        } else {
            check_attrs(&root_el.name, &root_el.pos, &attrs, &["version", "type", "id", "name"], &["version", "type"])?;
            let plugin = req(&attrs, "type", &root_el.pos)?.value.clone();
            let id = find(&attrs, "id").map(|a| a.value.clone()).filter(|v| !v.is_empty());
            let idx = self.nodes.len();
            if let Some(id) = &id {
                self.register_id(id, idx, &root_el.pos)?;
            }
            self.nodes.push(Node::new(kind, &plugin, id, root_el.pos.clone(), version));
            let name = self.prop_name(parent, include_attrs);
            self.push_prop(parent, name, NValue::Node(idx), root_el.pos.clone())?;
            let mut sub = FileCtx { version, resolver, root: idx, depth: ctx.depth + 1 };
            for child in &root_el.children {
                self.element(&mut sub, child, idx)?;
            }
        }
        Ok(())
    }
}

/// The `version` attribute of a file's root element.
fn root_version(root: &Element) -> Result<Version> {
    let Some(v) = root.attr("version") else {
        return Err(Error::at(
            &root.pos,
            format!("missing version attribute in root element <{}> (e.g. version=\"3.0.0\")", root.name),
        ));
    };
    parse_version(&v.value).ok_or_else(|| {
        Error::at(
            &v.pos,
            format!("invalid version number \"{}\" (expected major.minor.patch, e.g. \"3.0.0\")", v.value),
        )
    })
}

/// The root `<scene>` may repeat its own kind as `type="scene"`, nothing else.
fn check_scene_type(attrs: &[Attr]) -> Result<()> {
    match find(attrs, "type") {
        Some(t) if t.value != "scene" => {
            Err(Error::at(&t.pos, format!("unsupported scene type \"{}\" (only \"scene\")", t.value)))
        }
        _ => Ok(()),
    }
}

fn searched(r: &FileResolver) -> String {
    r.paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
}

/// `<float>`, `<integer>`, `<boolean>`, `<string>` and `<rgb>` values.
fn scalar_value(tag: &str, v: &Attr) -> Result<Value> {
    let s = v.value.as_str();
    let bad = |what: &str| Error::at(&v.pos, format!("could not parse {what} value \"{s}\""));
    Ok(match tag {
        "float" => Value::Float(parse_float(s).ok_or_else(|| bad("floating point"))?),
        "integer" => Value::Integer(parse_int(s).ok_or_else(|| {
            let hint =
                if parse_float(s).is_some() { " (an <integer> has no fraction or exponent; use <float>)" } else { "" };
            Error::at(&v.pos, format!("could not parse integer value \"{s}\"{hint}"))
        })?),
        "boolean" => Value::Bool(parse_bool(s).ok_or_else(|| {
            Error::at(&v.pos, format!("could not parse boolean value \"{s}\" -- must be \"true\" or \"false\""))
        })?),
        "string" => Value::String(s.to_string()),
        _ => {
            let toks = tokens(s);
            let nums: Option<Vec<f64>> = toks.iter().map(|t| parse_float(t)).collect();
            match (toks.len(), nums) {
                (1, Some(n)) => Value::Rgb(DVec3::splat(n[0])),
                (3, Some(n)) => Value::Rgb(DVec3::new(n[0], n[1], n[2])),
                _ => {
                    return Err(Error::at(
                        &v.pos,
                        format!(
                            "could not parse RGB value \"{s}\" (expected 1 or 3 numbers separated by commas or spaces)"
                        ),
                    ))
                }
            }
        }
    })
}
