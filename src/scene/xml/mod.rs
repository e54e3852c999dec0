//! Mitsuba 3 XML scene parser: text → [`ObjectDesc`] tree with a source position on everything.
//!
//! Follows Mitsuba 3.9's `src/core/parser.cpp`: it checks syntax, tags, attributes, value syntax,
//! versions, ids and references, includes and parameters, but not plugin or parameter names
//! (plugin constructors do that through [`crate::scene::desc::Props::finish`]).
//!
//! ```xml
//! <scene version="3.0.0">
//!     <default name="spp" value="64"/>                  <!-- $spp, unless -D spp=... -->
//!     <path value="assets"/>                            <!-- extra search folder -->
//!     <include filename="camera.xml"/>                  <!-- its objects are inserted here -->
//!     <bsdf type="dielectric" id="glass">
//!         <string name="int_ior" value="bk7"/>
//!     </bsdf>
//!     <shape type="sphere">
//!         <transform name="to_world">
//!             <scale value="0.5"/>
//!             <translate x="1" y="0" z="0"/>
//!         </transform>
//!         <ref id="glass"/>                             <!-- the same object, shared -->
//!         <medium type="homogeneous" name="interior">
//!             <rgb name="albedo" value="0.9, 0.8, 0.7"/>
//!             <spectrum name="sigma_t" value="400:0.5, 700:0.9"/>
//!         </medium>
//!     </shape>
//!     <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
//! </scene>
//! ```
//!
//! Stages: [`dom`] (XML → elements with positions), [`parser`] (tags → object nodes, `$param`
//! substitution, `<default>`, `<include>`, `<path>`, `<alias>`), [`build`] (upgrade of old
//! versions, `<ref>` resolution, cycle check, shared tree). Value syntax is in [`number`],
//! [`transform`] and [`spectrum`].
//!
//! Where this parser deliberately differs from Mitsuba 3.9 (all on input Mitsuba mishandles):
//! two nested objects with the same name are an error (Mitsuba keeps the last one silently),
//! version strings must be exactly `M.m.p`, a second root element or a duplicated attribute
//! is an error (pugixml ignores it), and files are searched in the scene's folder and `<path>`
//! folders only (not the current directory).

pub mod build;
pub mod dom;
pub mod number;
pub mod params;
pub mod parser;
pub mod spectrum;
pub mod transform;

pub use spectrum::spectrum_list_to_srgb;

use crate::scene::desc::ObjectDesc;
use crate::scene::error::{Error, Result};
use crate::scene::resolver::FileResolver;
use params::Params;
use parser::Parser;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

/// A parsed scene: the root `<scene>` object and the resolver for its asset files (the scene's
/// folder and the `<path>` folders).
#[derive(Debug)]
pub struct ParsedScene {
    pub root: Rc<ObjectDesc>,
    pub resolver: FileResolver,
}

/// Parse a scene file. `defines` are the `-D name=value` overrides, in order.
pub fn parse_file(path: &Path, defines: &[(String, String)]) -> Result<ParsedScene> {
    let name = path.display().to_string();
    let bytes =
        std::fs::read(path).map_err(|e| Error::in_file(&name, format!("could not read the scene file: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let ok = e.utf8_error().valid_up_to();
        let prefix = String::from_utf8_lossy(&e.as_bytes()[..ok]).into_owned();
        Error::at(&dom::LineIndex::new(&prefix, Arc::from(name.as_str())).pos(ok), "the file is not valid UTF-8")
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    parse(&text, &name, &dir, canonical, defines)
}

/// Parse text as if it were the file `file_name` located in `base_dir` (assets and includes
/// resolve against `base_dir`).
pub fn parse_str(text: &str, file_name: &str, base_dir: &Path, defines: &[(String, String)]) -> Result<ParsedScene> {
    let canonical = base_dir.join(file_name);
    let canonical = canonical.canonicalize().unwrap_or(canonical);
    parse(text, file_name, base_dir, canonical, defines)
}

fn parse(
    text: &str,
    file_name: &str,
    dir: &Path,
    canonical: PathBuf,
    defines: &[(String, String)],
) -> Result<ParsedScene> {
    if let Some((k, _)) = defines.iter().find(|(k, _)| k.is_empty()) {
        return Err(Error::msg(format!("empty parameter name in -D {k}=...")));
    }
    let dir = if dir.as_os_str().is_empty() { PathBuf::from(".") } else { dir.to_path_buf() };
    let mut resolver = FileResolver { paths: vec![dir] };
    let mut parser = Parser::new(Params::from_defines(defines));
    let root = parser.parse_main(text, Arc::from(file_name), canonical, &mut resolver)?;

    let unused = parser.params.unused();
    if !unused.is_empty() {
        return Err(Error::in_file(
            file_name,
            format!(
                "unused parameter{} -D {} (no attribute of the scene uses ${})",
                if unused.len() > 1 { "s" } else { "" },
                unused.join(", -D "),
                unused.iter().map(|u| u.split('=').next().unwrap_or("")).collect::<Vec<_>>().join(", $"),
            ),
        ));
    }
    build::upgrade(&mut parser.nodes)?;
    build::resolve_refs(&mut parser.nodes, &parser.ids)?;
    let root = build::build_tree(&parser.nodes, root)?;
    Ok(ParsedScene { root, resolver })
}
