//! Resource checks before work starts: the memory a film, mesh or texture will need, estimated
//! from its declared sizes, checked against the memory the machine has.
//!
//! A film of 65536 × 65536 pixels, a PLY header declaring 10^10 vertices or an image header
//! declaring 10^5 × 10^5 pixels would otherwise end in the allocator (an abort, or the
//! out-of-memory killer) instead of an error that names the parameter. The estimates count the
//! large buffers only (see each function) and are meant to be within a factor of two; a check
//! refuses only what cannot fit, so a scene near the limit may still run out later.
//!
//! Available memory is `MemAvailable` of `/proc/meminfo`. The environment variable
//! `SNEE_MEMORY_AVAILABLE` overrides it (bytes, or with a suffix `K`, `M`, `G`, `T`, powers of
//! 1024), for tests and for machines where a job is given less than the kernel reports. Where
//! neither is known (not Linux), nothing is refused.

use super::error::{Error, Result, SrcPos};

/// The override of the available memory (see the module documentation).
pub const MEMORY_ENV: &str = "SNEE_MEMORY_AVAILABLE";

/// Bytes the process can still allocate: `SNEE_MEMORY_AVAILABLE`, else `MemAvailable` of
/// `/proc/meminfo`, else `None` (unknown).
pub fn available_bytes() -> Option<u64> {
    if let Ok(v) = std::env::var(MEMORY_ENV) {
        return parse_size(&v);
    }
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    // "MemAvailable:   22817292 kB"
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// `"123"`, `"64K"`, `"1.5G"` → bytes (powers of 1024); `None` when malformed.
pub fn parse_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (num, unit) = match s.char_indices().last()? {
        (i, c) if c.is_ascii_alphabetic() => (&s[..i], c.to_ascii_uppercase()),
        _ => (s, 'B'),
    };
    let scale = match unit {
        'B' => 1u64,
        'K' => 1 << 10,
        'M' => 1 << 20,
        'G' => 1 << 30,
        'T' => 1 << 40,
        _ => return None,
    };
    let v: f64 = num.trim().parse().ok()?;
    (v.is_finite() && v >= 0.0).then(|| (v * scale as f64).min(u64::MAX as f64) as u64)
}

/// `1536` → `"1.5 KiB"`.
pub fn human(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

/// Refuse `needed` bytes when more than the available memory: `pos: <what> needs about N of
/// memory, but only M is available`.
pub fn check(needed: u64, what: &str, pos: &SrcPos) -> Result<()> {
    check_against(needed, available_bytes(), what, pos)
}

fn check_against(needed: u64, available: Option<u64>, what: &str, pos: &SrcPos) -> Result<()> {
    match available {
        Some(avail) if needed > avail => Err(Error::at(
            pos,
            format!(
                "{what} needs about {} of memory, but only {} is available{}",
                human(needed),
                human(avail),
                if std::env::var_os(MEMORY_ENV).is_some() { format!(" (set by {MEMORY_ENV})") } else { String::new() }
            ),
        )),
        _ => Ok(()),
    }
}

/// Memory of a render of `pixels` pixels with `channels` developed channels: the accumulation
/// block (channels and a weight per pixel), the developed image and the copy made when writing,
/// all `f32`. The filter border and the `m2.*` channels of `--moment` are not counted.
pub fn film_bytes(pixels: u64, channels: u64) -> u64 {
    pixels.saturating_mul(4 * ((channels + 1) + 2 * channels))
}

/// Memory of a triangle mesh: per vertex a position, normal and uv (32 bytes) held twice (as
/// loaded, and transformed to world space); per triangle its indices (12 bytes) and about 96
/// bytes while the BVH is built.
pub fn mesh_bytes(vertices: u64, triangles: u64) -> u64 {
    vertices.saturating_mul(64).saturating_add(triangles.saturating_mul(12 + 96))
}

/// Memory of a decoded image of `width × height` pixels with `channels` channels: the decoder's
/// buffer (at most 4 bytes per sample), the `f32` bitmap and the linear RGB texels (12 bytes).
pub fn image_bytes(width: u64, height: u64, channels: u64) -> u64 {
    width.saturating_mul(height).saturating_mul(channels.saturating_mul(8).saturating_add(12))
}

/// Declared size of an OpenEXR or PNG image from its header only: `(width, height, channels)`
/// of the first layer. `None` when the file cannot be read or the header is not understood
/// (the decoder then reports the problem).
pub fn image_header_size(path: &std::path::Path) -> Option<(u64, u64, u64)> {
    use std::io::Read;
    let mut head = [0u8; 26];
    let mut f = std::fs::File::open(path).ok()?;
    f.read_exact(&mut head).ok()?;
    if head.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]) && &head[12..16] == b"IHDR" {
        let be = |o: usize| u32::from_be_bytes([head[o], head[o + 1], head[o + 2], head[o + 3]]) as u64;
        // Colour type: 0 grey, 2 RGB, 3 palette (expanded to RGB(A)), 4 grey+alpha, 6 RGBA.
        let channels = match head[25] {
            0 => 1,
            4 => 2,
            2 => 3,
            _ => 4,
        };
        return Some((be(16), be(20), channels));
    }
    if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let f = std::io::BufReader::new(std::fs::File::open(path).ok()?);
        let meta = exr::meta::MetaData::read_from_buffered(f, false).ok()?;
        let h = meta.headers.first()?;
        return Some((h.layer_size.width() as u64, h.layer_size.height() as u64, h.channels.list.len() as u64));
    }
    None
}

/// Refuse an image file whose header declares more pixels than memory holds; `pos` is the
/// position of the parameter `param` naming the file (`param` may be empty).
pub fn check_image(path: &std::path::Path, param: &str, pos: &SrcPos) -> Result<()> {
    match image_header_size(path) {
        Some((w, h, c)) => {
            let prefix = if param.is_empty() { String::new() } else { format!("{param}: ") };
            check(image_bytes(w, h, c), &format!("{prefix}the image ({w} x {h}, {c} channels)"), pos)
        }
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("123"), Some(123));
        assert_eq!(parse_size("64k"), Some(64 << 10));
        assert_eq!(parse_size("1.5G"), Some(3 << 29));
        assert_eq!(parse_size("x"), None);
        assert_eq!(parse_size("-1"), None);
        assert_eq!(human(1536), "1.5 KiB");
        assert_eq!(human(12), "12 bytes");
    }

    #[test]
    fn refusal_names_what_and_where() {
        let pos = SrcPos::new("a.xml", 3, 9);
        let e = check_against(film_bytes(65536 * 65536, 3), Some(16 << 30), "film width x height", &pos).unwrap_err();
        assert_eq!(e.pos, Some(pos.clone()));
        assert!(e.msg.starts_with("film width x height needs about 160.0 GiB of memory, but only 16.0 GiB"), "{e}");
        assert!(check_against(1 << 20, Some(16 << 30), "x", &pos).is_ok());
        assert!(check_against(u64::MAX, None, "x", &pos).is_ok());
    }
}
