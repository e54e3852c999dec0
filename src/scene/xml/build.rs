//! Stage 3 of parsing: upgrade old scenes, resolve `<ref>`s, reject reference cycles, and
//! build the shared [`ObjectDesc`] tree (an object referenced twice is one `Rc`).

use super::number::{camel_to_snake, Version};
use super::parser::{NProp, NValue, Node};
use super::transform;
use crate::scene::desc::{ObjectDesc, Props, Value};
use crate::scene::error::{Error, Result, SrcPos};
use glam::DVec3;
use std::collections::HashMap;
use std::rc::Rc;

/// Mitsuba's `upgrade_from_v1`, applied to the objects of files with version < 2.0.0:
/// property names go from camelCase to snake_case, `diffuse`'s `diffuse_reflectance` becomes
/// `reflectance`, and `uoffset`/`voffset`/`uscale`/`vscale` become a `to_uv` transform.
pub fn upgrade(nodes: &mut [Node]) -> Result<()> {
    for node in nodes.iter_mut() {
        if node.version >= Version(2, 0, 0) {
            continue;
        }
        let old = node.version;
        for i in 0..node.props.len() {
            let new_name = camel_to_snake(&node.props[i].name);
            if new_name != node.props[i].name {
                rename(node, i, new_name, old)?;
            }
        }
        if node.plugin == "diffuse" {
            if let Some(i) = node.props.iter().position(|p| p.name == "diffuse_reflectance") {
                rename(node, i, "reflectance".to_string(), old)?;
            }
        }
        let mut offset = DVec3::ZERO;
        let mut scale = DVec3::ONE;
        let mut first_pos: Option<SrcPos> = None;
        for (name, slot, is_offset) in
            [("uoffset", 0, true), ("voffset", 1, true), ("uscale", 0, false), ("vscale", 1, false)]
        {
            let Some(i) = node.props.iter().position(|p| p.name == name) else { continue };
            let p = node.props.remove(i);
            let v = match p.value {
                NValue::Value(Value::Float(v)) => v,
                NValue::Value(Value::Integer(v)) => v as f64,
                _ => return Err(Error::at(&p.pos, format!("property \"{name}\" must be a float"))),
            };
            if is_offset {
                offset[slot] = v;
            } else {
                scale[slot] = v;
            }
            first_pos.get_or_insert(p.pos);
        }
        if let Some(pos) = first_pos {
            if let Some(prev) = node.props.iter().find(|p| p.name == "to_uv") {
                return Err(Error::at(
                    &pos,
                    format!(
                        "uoffset/voffset/uscale/vscale become \"to_uv\", which is already specified at {}",
                        prev.pos
                    ),
                ));
            }
            let m = transform::scale(scale) * transform::translate(offset);
            node.props.push(NProp { name: "to_uv".into(), value: NValue::Value(Value::Transform(m)), pos });
        }
    }
    Ok(())
}

fn rename(node: &mut Node, i: usize, new_name: String, version: Version) -> Result<()> {
    if let Some(other) = node.props.iter().find(|p| p.name == new_name) {
        return Err(Error::at(
            &node.props[i].pos,
            format!(
                "property \"{}\" of this version {version} scene is renamed \"{new_name}\", which is already specified at {}",
                node.props[i].name, other.pos
            ),
        ));
    }
    node.props[i].name = new_name;
    Ok(())
}

/// Replace every `<ref id>` by the node it names.
pub fn resolve_refs(nodes: &mut [Node], ids: &HashMap<String, (usize, SrcPos)>) -> Result<()> {
    for node in nodes.iter_mut() {
        for p in &mut node.props {
            if let NValue::Ref(id) = &p.value {
                let Some((target, _)) = ids.get(id) else {
                    let prop = if p.name.starts_with("_arg_") {
                        String::new()
                    } else {
                        format!(" in property \"{}\"", p.name)
                    };
                    return Err(Error::at(
                        &p.pos,
                        format!("unresolved reference to \"{id}\"{prop}: no object has id=\"{id}\""),
                    ));
                };
                p.value = NValue::Node(*target);
            }
        }
    }
    Ok(())
}

/// Build the tree below `root`, rejecting reference cycles. Iterative, so long reference chains
/// cannot overflow the stack.
pub fn build_tree(nodes: &[Node], root: usize) -> Result<Rc<ObjectDesc>> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        Open,
        Done,
    }
    let mut state = vec![State::New; nodes.len()];
    let mut built: Vec<Option<Rc<ObjectDesc>>> = vec![None; nodes.len()];
    // (node, index of the next property to visit)
    let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
    if root >= nodes.len() {
        return Err(Error::msg("internal error: empty scene"));
    }
    state[root] = State::Open;
    while let Some(top) = stack.last_mut() {
        let (n, next) = *top;
        let node = &nodes[n];
        if let Some(p) = node.props.get(next) {
            top.1 += 1;
            let NValue::Node(child) = p.value else { continue };
            match state.get(child) {
                Some(State::New) => {
                    state[child] = State::Open;
                    stack.push((child, 0));
                }
                Some(State::Open) => {
                    let start = stack.iter().position(|(s, _)| *s == child).unwrap_or(0);
                    let mut chain: Vec<String> = stack[start..].iter().map(|(s, _)| label(&nodes[*s], *s)).collect();
                    chain.push(label(&nodes[child], child));
                    return Err(Error::at(&p.pos, format!("circular reference: {}", chain.join(" -> "))));
                }
                Some(State::Done) => {}
                None => return Err(Error::at(&p.pos, "internal error: dangling object reference")),
            }
            continue;
        }
        // All children are built: build this node.
        let mut props = Props::new(node.kind, &node.plugin, node.pos.clone());
        for p in &node.props {
            let value = match &p.value {
                NValue::Value(v) => v.clone(),
                NValue::Node(c) => match built.get(*c).and_then(|b| b.clone()) {
                    Some(o) => Value::Object(o),
                    None => return Err(Error::at(&p.pos, "internal error: object built out of order")),
                },
                NValue::Ref(id) => return Err(Error::at(&p.pos, format!("unresolved reference to \"{id}\""))),
            };
            props.push(&p.name, value, p.pos.clone())?;
        }
        built[n] = Some(Rc::new(ObjectDesc {
            kind: node.kind,
            plugin: node.plugin.clone(),
            id: node.id.clone(),
            pos: node.pos.clone(),
            props,
        }));
        state[n] = State::Done;
        stack.pop();
    }
    built[root].clone().ok_or_else(|| Error::msg("internal error: root not built"))
}

fn label(node: &Node, index: usize) -> String {
    match &node.id {
        Some(id) => format!("\"{id}\""),
        None => format!("<{} type=\"{}\"> (object #{index})", node.kind.tag(), node.plugin),
    }
}
