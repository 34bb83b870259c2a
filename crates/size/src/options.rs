//! `SizeOptions`: every user setting of the size field, readable from TOML.
//! `crates/size/examples/sizes.toml` documents each key.
use crate::SizeError;
use parafront_geom::P3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Default gradation: a neighbour may be at most 1.2 times as large one
/// element away. Gentle enough for good tets next to small features, while
/// sizes still reach 10x the surface size within about 45 surface sizes.
pub const DEFAULT_GRADATION: f64 = 1.2;

/// Options of the size field. Defaults: no global size, `hmin = 0`,
/// `hmax = inf`, `gradation = 1.2`, surface growth on, no sources, no patch
/// sizes, no background grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeOptions {
    /// Global target size; also an upper bound everywhere (`hmax` becomes
    /// `min(hmax, h)`).
    #[serde(default)]
    pub h: Option<f64>,
    /// Lower clamp of the final size.
    #[serde(default)]
    pub hmin: f64,
    /// Upper clamp of the final size.
    #[serde(default = "infinity")]
    pub hmax: f64,
    /// Growth limit g >= 1: away from a point of size h_i the size is at most
    /// `h_i + (g - 1) * distance` (a linear cone, i.e. (g-1)-Lipschitz).
    #[serde(default = "default_gradation")]
    pub gradation: f64,
    /// Grow the size from the surface points (mean incident edge length).
    #[serde(default = "yes")]
    pub surface_growth: bool,
    /// Size sources ([`SourceSpec`]).
    #[serde(default)]
    pub sources: Vec<SourceSpec>,
    /// Patch tag -> size imposed at the points of that patch's triangles
    /// (only refines: the point size is min(mean edge length, patch size)).
    /// TOML keys are strings: `[patch_sizes]` then `3 = 0.01`.
    #[serde(default)]
    pub patch_sizes: BTreeMap<String, f64>,
    /// Background tet grid with a nodal size (read by the CLI).
    #[serde(default)]
    pub background: Option<PathBuf>,
}

fn infinity() -> f64 {
    f64::INFINITY
}
fn default_gradation() -> f64 {
    DEFAULT_GRADATION
}
fn yes() -> bool {
    true
}

impl Default for SizeOptions {
    fn default() -> Self {
        SizeOptions {
            h: None,
            hmin: 0.0,
            hmax: f64::INFINITY,
            gradation: DEFAULT_GRADATION,
            surface_growth: true,
            sources: Vec::new(),
            patch_sizes: BTreeMap::new(),
            background: None,
        }
    }
}

/// A size source. Every kind has a core (within distance `r0` of its
/// geometry) where the size is `h0`; outside it grows linearly:
/// `h = h0 + (growth - 1) * (d - r0)`, `d` the distance to the geometry.
/// `growth` defaults to the global gradation. The linear form matches the
/// gradation limit, so a source never makes the field steeper than asked.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum SourceSpec {
    /// Around a point.
    Point {
        /// The point.
        center: P3,
        /// The size in the core.
        h0: f64,
        /// Radius of the core around the geometry (default 0).
        #[serde(default)]
        r0: f64,
        /// Growth outside the core (default: the gradation).
        #[serde(default)]
        growth: Option<f64>,
    },
    /// Around the segment from `a` to `b`.
    Segment {
        /// One end.
        a: P3,
        /// The other end.
        b: P3,
        /// The size in the core.
        h0: f64,
        /// Radius of the core around the geometry (default 0).
        #[serde(default)]
        r0: f64,
        /// Growth outside the core (default: the gradation).
        #[serde(default)]
        growth: Option<f64>,
    },
    /// Around the spherical surface of `radius` about `center` (a shell; for a
    /// solid ball use a point source with `r0 = radius`).
    Sphere {
        /// The sphere's center.
        center: P3,
        /// Its radius.
        radius: f64,
        /// The size in the core.
        h0: f64,
        /// Radius of the core around the geometry (default 0).
        #[serde(default)]
        r0: f64,
        /// Growth outside the core (default: the gradation).
        #[serde(default)]
        growth: Option<f64>,
    },
    /// The solid axis-aligned box `[min, max]` (d = 0 inside).
    Box {
        /// The corner with the smallest coordinates.
        min: P3,
        /// The corner with the largest coordinates.
        max: P3,
        /// The size in the core.
        h0: f64,
        /// Radius of the core around the geometry (default 0).
        #[serde(default)]
        r0: f64,
        /// Growth outside the core (default: the gradation).
        #[serde(default)]
        growth: Option<f64>,
    },
}

impl SourceSpec {
    /// Its `kind` in TOML.
    pub fn kind(&self) -> &'static str {
        match self {
            SourceSpec::Point { .. } => "point",
            SourceSpec::Segment { .. } => "segment",
            SourceSpec::Sphere { .. } => "sphere",
            SourceSpec::Box { .. } => "box",
        }
    }
    /// (h0, r0, growth) common to every kind.
    pub(crate) fn params(&self) -> (f64, f64, Option<f64>) {
        match *self {
            SourceSpec::Point { h0, r0, growth, .. }
            | SourceSpec::Segment { h0, r0, growth, .. }
            | SourceSpec::Sphere { h0, r0, growth, .. }
            | SourceSpec::Box { h0, r0, growth, .. } => (h0, r0, growth),
        }
    }
    fn points(&self) -> Vec<P3> {
        match *self {
            SourceSpec::Point { center, .. } | SourceSpec::Sphere { center, .. } => vec![center],
            SourceSpec::Segment { a, b, .. } => vec![a, b],
            SourceSpec::Box { min, max, .. } => vec![min, max],
        }
    }
}

impl SizeOptions {
    /// Parses TOML; `origin` (a file name) prefixes the error, whose text from
    /// `toml` names the line, column and offending key or value.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<SizeOptions, SizeError> {
        let o: SizeOptions = toml::from_str(text).map_err(|e| SizeError::Toml {
            origin: origin.to_string(),
            msg: e.to_string(),
        })?;
        o.validate()?;
        Ok(o)
    }

    /// Reads and validates a TOML file ([`SizeOptions::from_toml_str`]).
    pub fn from_toml_file(path: &Path) -> Result<SizeOptions, SizeError> {
        let text = std::fs::read_to_string(path).map_err(|e| SizeError::Io {
            path: path.to_path_buf(),
            msg: e.to_string(),
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// As TOML, which [`SizeOptions::from_toml_str`] reads back (empty if
    /// it cannot be written).
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// The upper clamp: `min(hmax, h)`.
    pub fn cap(&self) -> f64 {
        self.h.map_or(self.hmax, |h| h.min(self.hmax))
    }

    /// Parsed patch sizes (keys must be u32 tags).
    pub fn patch_size_map(&self) -> Result<BTreeMap<u32, f64>, SizeError> {
        let mut m = BTreeMap::new();
        for (k, &v) in &self.patch_sizes {
            let tag: u32 = k.trim().parse().map_err(|_| SizeError::Invalid {
                what: format!("patch_sizes key {k:?}"),
                why: "must be a non-negative integer patch tag".into(),
            })?;
            pos_finite(&format!("patch_sizes.{k}"), v)?;
            m.insert(tag, v);
        }
        Ok(m)
    }

    /// Checks every value; the error names the key.
    pub fn validate(&self) -> Result<(), SizeError> {
        if let Some(h) = self.h {
            pos_finite("h", h)?;
        }
        if !(self.hmin >= 0.0 && self.hmin.is_finite()) {
            return Err(invalid("hmin", self.hmin, "must be finite and >= 0"));
        }
        if self.hmax.is_nan() || self.hmax <= 0.0 || self.hmax < self.hmin {
            return Err(invalid("hmax", self.hmax, "must be > 0 and >= hmin"));
        }
        if let Some(h) = self.h {
            if h < self.hmin {
                return Err(invalid("h", h, "must be >= hmin"));
            }
        }
        check_growth("gradation", self.gradation)?;
        for (i, s) in self.sources.iter().enumerate() {
            let name = |k: &str| format!("sources[{i}] ({}) {k}", s.kind());
            let (h0, r0, growth) = s.params();
            pos_finite(&name("h0"), h0)?;
            if !(r0 >= 0.0 && r0.is_finite()) {
                return Err(invalid(&name("r0"), r0, "must be finite and >= 0"));
            }
            if let Some(g) = growth {
                check_growth(&name("growth"), g)?;
            }
            for p in s.points() {
                if !p.iter().all(|x| x.is_finite()) {
                    return Err(SizeError::Invalid {
                        what: name("coordinates"),
                        why: format!("{p:?} is not finite"),
                    });
                }
            }
            match *s {
                SourceSpec::Sphere { radius, .. } if !(radius >= 0.0 && radius.is_finite()) => {
                    return Err(invalid(&name("radius"), radius, "must be finite and >= 0"));
                }
                SourceSpec::Box { min, max, .. } if (0..3).any(|k| min[k] > max[k]) => {
                    return Err(SizeError::Invalid {
                        what: name("min/max"),
                        why: format!("min {min:?} exceeds max {max:?}"),
                    });
                }
                _ => {}
            }
        }
        self.patch_size_map()?;
        Ok(())
    }
}

fn invalid(what: &str, v: f64, why: &str) -> SizeError {
    SizeError::Invalid {
        what: what.to_string(),
        why: format!("{why}, got {v}"),
    }
}
fn pos_finite(what: &str, v: f64) -> Result<(), SizeError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(invalid(what, v, "must be finite and > 0"))
    }
}
fn check_growth(what: &str, g: f64) -> Result<(), SizeError> {
    // Above 10 the "gradation" no longer limits anything useful.
    if (1.0..=10.0).contains(&g) {
        Ok(())
    } else {
        Err(invalid(what, g, "must be in [1, 10]"))
    }
}
