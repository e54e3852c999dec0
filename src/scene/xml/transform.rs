//! `<transform>` operations, composed as Mitsuba 3.9 composes them: each operation, in document
//! order, multiplies the matrix built so far from the left (`M = op · M`), in double precision.
//!
//! ```xml
//! <transform name="to_world">
//!     <scale value="2"/>                              <!-- 1 value: uniform -->
//!     <rotate y="1" angle="30"/>                      <!-- degrees; the axis is NOT normalized -->
//!     <translate x="1" y="0" z="-3"/>                 <!-- or value="1, 0, -3"; value="1" is (1,1,1) -->
//!     <matrix value="0 -1 0 0  1 0 0 0  0 0 1 0  0 0 0 1"/>  <!-- 9 or 16 values, row-major -->
//!     <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>
//! </transform>
//! ```
//! Mitsuba quirks kept on purpose: `rotate` uses its axis as given (a non-unit axis also
//! scales), `matrix` drops the bottom (projective) row, and `lookat` without `up` (or with a zero
//! `up`) picks one from the viewing direction.

use super::dom::{check_attrs, find, Attr};
use super::number::{parse_float, tokens};
use crate::scene::error::{Error, Result, SrcPos};
use glam::{DMat4, DVec3, DVec4};

/// Apply one operation element (attributes already `$`-substituted) to `m`.
pub fn apply_op(tag: &str, pos: &SrcPos, attrs: &mut Vec<Attr>, m: DMat4) -> Result<DMat4> {
    let op = match tag {
        "translate" => {
            expand_value_to_xyz(tag, attrs)?;
            check_attrs(tag, pos, attrs, &["x", "y", "z"], &[])?;
            translate(parse_xyz(attrs, 0.0)?)
        }
        "scale" => {
            expand_value_to_xyz(tag, attrs)?;
            check_attrs(tag, pos, attrs, &["x", "y", "z"], &[])?;
            scale(parse_xyz(attrs, 1.0)?)
        }
        "rotate" => {
            expand_value_to_xyz(tag, attrs)?;
            check_attrs(tag, pos, attrs, &["angle", "x", "y", "z"], &["angle"])?;
            let axis = parse_xyz(attrs, 0.0)?;
            if axis == DVec3::ZERO {
                return Err(Error::at(pos, "rotation axis cannot be zero (give x, y, z or value)"));
            }
            let angle = number(find(attrs, "angle"), "angle")?;
            rotate(axis, angle)
        }
        "lookat" => {
            check_attrs(tag, pos, attrs, &["origin", "target", "up"], &["origin", "target"])?;
            let origin = vector3(find(attrs, "origin"))?;
            let target = vector3(find(attrs, "target"))?;
            let up = match find(attrs, "up") {
                Some(a) if !a.value.is_empty() => vector3(Some(a))?,
                _ => DVec3::ZERO,
            };
            let result = look_at(origin, target, up) * m;
            if result.to_cols_array().iter().any(|v| v.is_nan()) {
                return Err(Error::at(
                    pos,
                    "invalid lookat transformation (origin equals target, or up is parallel to the viewing direction)",
                ));
            }
            return Ok(result);
        }
        "matrix" => {
            check_attrs(tag, pos, attrs, &["value"], &["value"])?;
            let Some(a) = find(attrs, "value") else { return Err(Error::at(pos, "missing \"value\"")) };
            let toks = tokens(&a.value);
            let n = match toks.len() {
                16 => 4,
                9 => 3,
                k => return Err(Error::at(&a.pos, format!("matrix must have 9 or 16 values, got {k}"))),
            };
            let mut rows = [[0.0f64; 4]; 4];
            for (i, row) in rows.iter_mut().enumerate() {
                row[i] = 1.0;
            }
            for (k, t) in toks.iter().enumerate() {
                let v =
                    parse_float(t).ok_or_else(|| Error::at(&a.pos, format!("could not parse matrix value \"{t}\"")))?;
                rows[k / n][k % n] = v;
            }
            // An affine transform: the bottom row is (0, 0, 0, 1) whatever was given.
            rows[3] = [0.0, 0.0, 0.0, 1.0];
            from_rows(rows)
        }
        "lookAt" => {
            return Err(Error::at(pos, "unexpected <lookAt> element inside <transform> (Mitsuba 3 spells it <lookat>)"))
        }
        other => {
            return Err(Error::at(
                pos,
                format!(
                "unexpected <{other}> element inside <transform> (expected translate, rotate, scale, matrix or lookat)"
            ),
            ))
        }
    };
    Ok(op * m)
}

/// A matrix from its rows (Mitsuba's `m(i, j)` is row i, column j).
pub fn from_rows(r: [[f64; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&r).transpose()
}

pub fn translate(v: DVec3) -> DMat4 {
    DMat4::from_translation(v)
}

pub fn scale(v: DVec3) -> DMat4 {
    DMat4::from_scale(v)
}

/// Mitsuba's `rotate(axis, angle)`: `cos θ·I + (1 − cos θ)·a·aᵀ + sin θ·[a]×` with the axis as
/// given (not normalized) and `angle` in degrees.
pub fn rotate(a: DVec3, angle_deg: f64) -> DMat4 {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let k = 1.0 - c;
    from_rows([
        [a.x * a.x * k + c, a.x * a.y * k - a.z * s, a.x * a.z * k + a.y * s, 0.0],
        [a.y * a.x * k + a.z * s, a.y * a.y * k + c, a.y * a.z * k - a.x * s, 0.0],
        [a.z * a.x * k - a.y * s, a.z * a.y * k + a.x * s, a.z * a.z * k + c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

/// Mitsuba's `coordinate_system(n).0` (Duff et al. 2017).
fn coordinate_system_s(n: DVec3) -> DVec3 {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    DVec3::new(n.x * n.x * a * sign + 1.0, b * sign, -sign * n.x)
}

/// Mitsuba's `look_at`: columns (left, up', dir, origin); a zero `up` is replaced by a vector
/// perpendicular to the viewing direction. Degenerate input produces NaNs (checked by the caller).
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> DMat4 {
    let normalize = |v: DVec3| v / v.length();
    let dir = normalize(target - origin);
    let up = if up == DVec3::ZERO { coordinate_system_s(dir) } else { up };
    let left = normalize(up.cross(dir));
    let new_up = dir.cross(left);
    DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        DVec4::new(origin.x, origin.y, origin.z, 1.0),
    )
}

/// Mitsuba's `expand_value_to_xyz`: `value` with 1 number sets x = y = z, with 3 numbers sets
/// x, y, z; it cannot be combined with x/y/z.
pub fn expand_value_to_xyz(tag: &str, attrs: &mut Vec<Attr>) -> Result<()> {
    let Some(idx) = attrs.iter().position(|a| a.name == "value") else { return Ok(()) };
    let value = attrs.remove(idx);
    if attrs.iter().any(|a| matches!(a.name.as_str(), "x" | "y" | "z")) {
        return Err(Error::at(&value.pos, format!("<{tag}> cannot mix \"value\" and \"x\"/\"y\"/\"z\" attributes")));
    }
    let toks = tokens(&value.value);
    let xyz: [&str; 3] = match toks.as_slice() {
        [v] => [v, v, v],
        [x, y, z] => [x, y, z],
        _ => {
            return Err(Error::at(
                &value.pos,
                format!("\"value\" attribute of <{tag}> must have exactly 1 or 3 numbers, got {}", toks.len()),
            ))
        }
    };
    for (name, v) in ["x", "y", "z"].into_iter().zip(xyz) {
        attrs.push(Attr { name: name.to_string(), value: v.to_string(), pos: value.pos.clone() });
    }
    Ok(())
}

/// x, y, z attributes as a vector; missing components take `default`.
pub fn parse_xyz(attrs: &[Attr], default: f64) -> Result<DVec3> {
    let comp = |n: &str| -> Result<f64> {
        match find(attrs, n) {
            None => Ok(default),
            Some(a) => number(Some(a), n),
        }
    };
    Ok(DVec3::new(comp("x")?, comp("y")?, comp("z")?))
}

fn number(a: Option<&Attr>, what: &str) -> Result<f64> {
    let a = a.ok_or_else(|| Error::msg(format!("missing \"{what}\"")))?;
    parse_float(&a.value)
        .ok_or_else(|| Error::at(&a.pos, format!("could not parse floating point value \"{}\" of \"{what}\"", a.value)))
}

/// Exactly three comma/space separated numbers.
fn vector3(a: Option<&Attr>) -> Result<DVec3> {
    let a = a.ok_or_else(|| Error::msg("missing vector attribute"))?;
    let toks = tokens(&a.value);
    if toks.len() != 3 {
        return Err(Error::at(
            &a.pos,
            format!("expected 3 values in \"{}\", got {}: \"{}\"", a.name, toks.len(), a.value),
        ));
    }
    let mut v = [0.0; 3];
    for (slot, t) in v.iter_mut().zip(&toks) {
        *slot = parse_float(t).ok_or_else(|| {
            Error::at(&a.pos, format!("could not parse floating point value \"{t}\" in \"{}\"", a.name))
        })?;
    }
    Ok(DVec3::from_array(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DMat4, rows: [[f64; 4]; 4]) -> bool {
        let b = from_rows(rows);
        a.to_cols_array().iter().zip(b.to_cols_array()).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn rotate_keeps_the_axis_length_like_mitsuba() {
        // Mitsuba 3.9.1: <rotate x="2" angle="90"/>.
        assert!(close(
            rotate(DVec3::new(2.0, 0.0, 0.0), 90.0),
            [[4.0, 0.0, 0.0, 0.0], [0.0, 0.0, -2.0, 0.0], [0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
        ));
        // <rotate value="1" angle="45"/>.
        assert!(close(
            rotate(DVec3::ONE, 45.0),
            [[1.0, -0.414214, 1.0, 0.0], [1.0, 1.0, -0.414214, 0.0], [-0.414214, 1.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
        ));
    }

    #[test]
    #[allow(clippy::approx_constant)] // numbers printed by Mitsuba
    fn look_at_like_mitsuba() {
        // <lookat origin="0 0 0" target="0 0 1"/> (no up).
        assert!(close(
            look_at(DVec3::ZERO, DVec3::Z, DVec3::ZERO),
            [[0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
        ));
        // <lookat origin="1,2,3" target="4, 5, 6" up="0,0,1"/>.
        assert!(close(
            look_at(DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0), DVec3::Z),
            [
                [-0.707107, -0.408248, 0.57735, 1.0],
                [0.707107, -0.408248, 0.57735, 2.0],
                [0.0, 0.816497, 0.57735, 3.0],
                [0.0, 0.0, 0.0, 1.0]
            ]
        ));
        assert!(look_at(DVec3::ONE, DVec3::ONE, DVec3::Y).to_cols_array().iter().any(|v| v.is_nan()));
    }
}
