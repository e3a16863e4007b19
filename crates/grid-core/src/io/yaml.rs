//! The map_server YAML: parsing with precise messages, validation, and writing.

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

use super::format_error;
use crate::{Error, Pose2, Result};

/// A map_server YAML is a few hundred bytes; anything this large is not one, and refusing it
/// keeps a mistaken argument (a log file, a bag) from being read into memory.
const MAX_YAML_BYTES: u64 = 1 << 20;

/// How pixel values become occupancy: map_server's `mode:` key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum MapMode {
    /// Occupied, free or unknown by the two thresholds (the default).
    #[default]
    Trinary,
    /// Like trinary, but values between the thresholds keep their probability; transparent
    /// pixels are unknown.
    Scale,
    /// The pixel value is the occupancy percentage (`0..=100`, others unknown).
    Raw,
}

impl MapMode {
    /// The YAML spelling: `trinary`, `scale` or `raw`.
    pub fn as_str(self) -> &'static str {
        match self {
            MapMode::Trinary => "trinary",
            MapMode::Scale => "scale",
            MapMode::Raw => "raw",
        }
    }

    /// Parse the YAML spelling; `None` for anything else.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "trinary" => Some(MapMode::Trinary),
            "scale" => Some(MapMode::Scale),
            "raw" => Some(MapMode::Raw),
            _ => None,
        }
    }
}

impl fmt::Display for MapMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The content of a map_server YAML file.
#[derive(Debug, Clone, PartialEq)]
pub struct MapMetadata {
    /// The `image:` entry as written (relative to the YAML's folder unless absolute).
    pub image: PathBuf,
    /// Metres per cell, finite and positive.
    pub resolution: f64,
    /// Pose of the lower-left corner of the lower-left cell, `[x, y, yaw]`.
    pub origin: Pose2,
    /// `negate: 1`: dark pixels are free.
    pub negate: bool,
    /// `p` above this is occupied; in `[0, 1]`.
    pub occupied_thresh: f64,
    /// `p` below this is free; in `[0, 1]` and below `occupied_thresh`.
    pub free_thresh: f64,
    /// `mode:`; trinary when absent.
    pub mode: MapMode,
}

impl MapMetadata {
    /// Read and validate the YAML file at `path`.
    pub fn read_yaml(path: &Path) -> Result<Self> {
        let io_err = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io_err)?;
        let mut bytes = Vec::new();
        file.take(MAX_YAML_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io_err)?;
        if bytes.len() as u64 > MAX_YAML_BYTES {
            return Err(format_error(
                path,
                format!(
                    "larger than {MAX_YAML_BYTES} bytes; a map_server YAML is a few lines of text"
                ),
            ));
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| format_error(path, "not a text file (invalid UTF-8)"))?;
        Self::parse_yaml(&text, path)
    }

    /// Parse and validate YAML text; `path` only names the file in errors.
    pub fn parse_yaml(text: &str, path: &Path) -> Result<Self> {
        if text.trim().is_empty() {
            return Err(format_error(path, "empty YAML file"));
        }
        // Let `.nan`/`.inf` through so that validation names the key they are in.
        let mut options = serde_saphyr::Options::default();
        options.non_finite_float_policy = serde_saphyr::NonFiniteFloatPolicy::PassThrough;
        // Duplicates reach our visitor, so that the message names the key in plain words.
        options.duplicate_keys = serde_saphyr::DuplicateKeyPolicy::PassThrough;
        let value: YamlValue = serde_saphyr::from_str_with_options(text, options).map_err(|e| {
            format_error(
                path,
                format!(
                    "invalid YAML: {}",
                    one_line(&e.without_snippet().to_string())
                ),
            )
        })?;
        let YamlValue::Map(entries) = value else {
            return Err(format_error(
                path,
                format!(
                    "expected a map_server YAML (keys image, resolution, origin, negate, \
                     occupied_thresh, free_thresh), found {}",
                    value.describe()
                ),
            ));
        };
        for (i, (key, _)) in entries.iter().enumerate() {
            if entries[..i].iter().any(|(k, _)| k == key) {
                return Err(format_error(
                    path,
                    format!("key `{key}` appears more than once"),
                ));
            }
        }
        let get = |key: &str| entries.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let required = |key: &'static str, what: &str| {
            get(key).ok_or_else(|| format_error(path, format!("missing key `{key}` ({what})")))
        };
        let wrong = |key: &str, expected: &str, found: &YamlValue| {
            format_error(
                path,
                format!("key `{key}` must be {expected}, found {}", found.describe()),
            )
        };
        let number = |key: &'static str, what: &str| -> Result<f64> {
            let v = required(key, what)?;
            v.as_f64().ok_or_else(|| wrong(key, "a number", v))
        };

        let image = match required("image", "the image file name")? {
            YamlValue::Str(s) if !s.trim().is_empty() => PathBuf::from(s.trim()),
            v => return Err(wrong("image", "an image file name", v)),
        };
        let resolution = number("resolution", "metres per cell")?;
        let origin = match required("origin", "[x, y, yaw] of the lower-left corner")? {
            YamlValue::Seq(items) if items.len() == 3 => {
                let mut xyz = [0.0; 3];
                for (slot, item) in xyz.iter_mut().zip(items) {
                    *slot = item
                        .as_f64()
                        .ok_or_else(|| wrong("origin", "a list of 3 numbers [x, y, yaw]", item))?;
                }
                Pose2::new(xyz[0], xyz[1], xyz[2])
            }
            v => return Err(wrong("origin", "a list of 3 numbers [x, y, yaw]", v)),
        };
        let negate = match required("negate", "0 or 1")? {
            YamlValue::Int(0) | YamlValue::Bool(false) => false,
            YamlValue::Int(1) | YamlValue::Bool(true) => true,
            v => return Err(wrong("negate", "0 or 1", v)),
        };
        let occupied_thresh = number("occupied_thresh", "a probability in [0, 1]")?;
        let free_thresh = number("free_thresh", "a probability in [0, 1]")?;
        let mode = match get("mode") {
            None | Some(YamlValue::Null) => MapMode::Trinary,
            Some(YamlValue::Str(s)) if MapMode::parse(s.trim()).is_some() => {
                MapMode::parse(s.trim()).unwrap_or_default()
            }
            Some(v) => return Err(wrong("mode", "trinary, scale or raw", v)),
        };
        let meta = Self {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh,
            free_thresh,
            mode,
        };
        meta.validate(path)?;
        Ok(meta)
    }

    /// Check the values: resolution finite and positive, origin finite, thresholds in `[0, 1]`
    /// with `free_thresh < occupied_thresh`. `path` names the file in the error.
    pub fn validate(&self, path: &Path) -> Result<()> {
        let fail = |reason: String| Err(format_error(path, reason));
        if !(self.resolution.is_finite() && self.resolution > 0.0) {
            return fail(format!(
                "resolution must be a positive number of metres per cell, found {}",
                self.resolution
            ));
        }
        let o = self.origin;
        if !(o.x.is_finite() && o.y.is_finite() && o.yaw.is_finite()) {
            return fail(format!(
                "origin must be 3 finite numbers [x, y, yaw], found [{}, {}, {}]",
                o.x, o.y, o.yaw
            ));
        }
        for (key, t) in [
            ("occupied_thresh", self.occupied_thresh),
            ("free_thresh", self.free_thresh),
        ] {
            if !(0.0..=1.0).contains(&t) {
                return fail(format!("{key} must be between 0 and 1, found {t}"));
            }
        }
        if self.free_thresh >= self.occupied_thresh {
            return fail(format!(
                "free_thresh ({}) must be less than occupied_thresh ({})",
                self.free_thresh, self.occupied_thresh
            ));
        }
        Ok(())
    }

    /// The image file: `image` resolved against the folder of the YAML at `yaml_path`.
    pub fn image_path(&self, yaml_path: &Path) -> PathBuf {
        match yaml_path.parent() {
            Some(dir) if self.image.is_relative() => dir.join(&self.image),
            _ => self.image.clone(),
        }
    }

    /// The YAML text, keys in map_saver's order. Floats are written so that they read back
    /// bit-identical (also by YAML 1.1 parsers, which want a `.` and a signed exponent).
    pub fn to_yaml(&self) -> String {
        let o = self.origin;
        format!(
            "image: {}\nmode: {}\nresolution: {}\norigin: [{}, {}, {}]\nnegate: {}\n\
             occupied_thresh: {}\nfree_thresh: {}\n",
            yaml_string(&self.image.to_string_lossy()),
            self.mode,
            yaml_float(self.resolution),
            yaml_float(o.x),
            yaml_float(o.y),
            yaml_float(o.yaw),
            u8::from(self.negate),
            yaml_float(self.occupied_thresh),
            yaml_float(self.free_thresh),
        )
    }
}

/// Shortest round-trip text of a finite float, always with a `.` and a signed exponent if any.
pub(crate) fn yaml_float(v: f64) -> String {
    // `{:?}` is Rust's shortest round-trip form: "0.05", "5.0", "1e-7", "1.5e20".
    let s = format!("{v:?}");
    match s.split_once('e') {
        Some((mantissa, exp)) => {
            let mantissa = if mantissa.contains('.') {
                mantissa.to_string()
            } else {
                format!("{mantissa}.0")
            };
            let exp = if exp.starts_with('-') {
                exp.to_string()
            } else {
                format!("+{exp}")
            };
            format!("{mantissa}e{exp}")
        }
        None => s,
    }
}

/// A plain scalar when that is unambiguous (as map_saver writes file names), else double-quoted.
fn yaml_string(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-/+".contains(c))
        && s.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '/');
    if plain {
        s.to_string()
    } else {
        let mut out = String::from("\"");
        for c in s.chars() {
            match c {
                '"' => out.push_str("\\\""),
                '\\' => out.push_str("\\\\"),
                c if c.is_control() => out.push_str(&format!("\\u{:04x}", c as u32)),
                c => out.push(c),
            }
        }
        out.push('"');
        out
    }
}

/// Collapse an error message to one line.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Just enough of a YAML document model to check every key ourselves and say precisely what is
/// wrong (a typed serde struct would only say "invalid type" without the key).
#[derive(Debug, Clone, PartialEq)]
enum YamlValue {
    Null,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(String),
    Seq(Vec<YamlValue>),
    Map(Vec<(String, YamlValue)>),
}

impl YamlValue {
    fn as_f64(&self) -> Option<f64> {
        match *self {
            YamlValue::Int(i) => Some(i as f64),
            YamlValue::Float(f) => Some(f),
            _ => None,
        }
    }

    /// What the user wrote, in words: "a string (\"abc\")", "a list of 2 items", ...
    fn describe(&self) -> String {
        match self {
            YamlValue::Null => "nothing (null)".into(),
            YamlValue::Bool(b) => format!("{b}"),
            YamlValue::Int(i) => format!("{i}"),
            YamlValue::Float(f) => format!("{f}"),
            YamlValue::Str(s) => {
                let short: String = s.chars().take(40).collect();
                let dots = if short.len() < s.len() { "..." } else { "" };
                format!("the text \"{short}{dots}\"")
            }
            YamlValue::Seq(items) => format!("a list of {} items", items.len()),
            YamlValue::Map(entries) => format!("a map of {} keys", entries.len()),
        }
    }
}

impl<'de> Deserialize<'de> for YamlValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(YamlVisitor)
    }
}

struct YamlVisitor;

impl<'de> Visitor<'de> for YamlVisitor {
    type Value = YamlValue;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a YAML value")
    }
    fn visit_unit<E>(self) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Null)
    }
    fn visit_none<E>(self) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Null)
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> std::result::Result<YamlValue, D::Error> {
        YamlValue::deserialize(d)
    }
    fn visit_bool<E>(self, v: bool) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Int(v))
    }
    fn visit_u64<E>(self, v: u64) -> std::result::Result<YamlValue, E> {
        Ok(i64::try_from(v).map_or(YamlValue::Float(v as f64), YamlValue::Int))
    }
    fn visit_i128<E>(self, v: i128) -> std::result::Result<YamlValue, E> {
        Ok(i64::try_from(v).map_or(YamlValue::Float(v as f64), YamlValue::Int))
    }
    fn visit_u128<E>(self, v: u128) -> std::result::Result<YamlValue, E> {
        Ok(i64::try_from(v).map_or(YamlValue::Float(v as f64), YamlValue::Int))
    }
    fn visit_f64<E>(self, v: f64) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Float(v))
    }
    fn visit_str<E>(self, v: &str) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Str(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> std::result::Result<YamlValue, E> {
        Ok(YamlValue::Str(v))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<YamlValue, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<YamlValue>()? {
            items.push(item);
        }
        Ok(YamlValue::Seq(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<YamlValue, A::Error> {
        let mut entries = Vec::new();
        while let Some(key) = map.next_key::<YamlValue>()? {
            let key = match key {
                YamlValue::Str(s) => s,
                other => other.describe(),
            };
            entries.push((key, map.next_value::<YamlValue>()?));
        }
        Ok(YamlValue::Map(entries))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_read_back_exactly_and_look_like_yaml_floats() {
        for v in [
            0.05,
            5.0,
            -0.0,
            1e-7,
            1.5e20,
            -12.5,
            0.1 + 0.2,
            f64::MIN_POSITIVE,
        ] {
            let s = yaml_float(v);
            assert!(s.contains('.'), "{s}");
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        assert_eq!(yaml_float(1e-7), "1.0e-7");
        assert_eq!(yaml_float(1.5e20), "1.5e+20");
    }

    #[test]
    fn odd_file_names_are_quoted() {
        assert_eq!(yaml_string("map.pgm"), "map.pgm");
        assert_eq!(yaml_string("a: b.pgm"), "\"a: b.pgm\"");
        assert_eq!(yaml_string("-x.pgm"), "\"-x.pgm\"");
    }
}
