//! Integrand specifications as text: `disk`, `ball`, `gaussian` with overrides, `grid:FILE`
//! (also `image:FILE`) for a function tabulated in a text or PNG file (2D; see
//! [`super::read_grid_file`]), `polygon:x,y;x,y;…` (or `polygon:@FILE`, one vertex `x y` per
//! line) and `edge:theta=DEGREES,offset=FRACTION,a=HEIGHT` (2D; see [`super::Polygon`]).
//!
//! `disk:r=0.2,a=2.2568`, `gaussian:sigma=0.0705,a=8`, `gaussian:c=0.3;0.5`. Keys: `r` (ball
//! radius), `sigma` (Gaussian width), `a` (height), `c` (centre: one value for every axis, or
//! `d` values separated by `;`). Defaults: ball `r = 0.25`, Gaussian `sigma = 0.1`, centre 0.5
//! in every coordinate, `a = 1`. A key may appear once.

use super::{read_grid_file, AnisotropicGaussian, Ball, Gaussian, GridMeaning, Integrand, Polygon};
use crate::error::{invalid, Error, Result};
use serde::Serialize;
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

/// The kinds of integrand this crate provides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum IntegrandKind {
    /// A ball (a disk in 2D, an interval in 1D) of constant height.
    Ball,
    /// An isotropic Gaussian.
    Gaussian,
    /// A function tabulated on a grid of cells (an image, a text grid).
    Grid,
    /// A polygon's indicator, or an edge (a half-plane clipped to the square).
    Polygon,
    /// An anisotropic Gaussian, truncated to the square where it crosses the faces.
    AnisotropicGaussian,
}

impl IntegrandKind {
    /// A short name, used in file names and tables: `ball`, `gaussian`, `grid`.
    pub fn name(self) -> &'static str {
        match self {
            IntegrandKind::Ball => "ball",
            IntegrandKind::Gaussian => "gaussian",
            IntegrandKind::Grid => "grid",
            IntegrandKind::Polygon => "polygon",
            IntegrandKind::AnisotropicGaussian => "agaussian",
        }
    }
}

impl fmt::Display for IntegrandKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A parsed integrand specification (its kind and parameters), buildable in any dimension.
#[derive(Debug, Clone, PartialEq)]
pub enum IntegrandSpec {
    /// A ball of `radius` and `height`, centred at `centre` (0.5 on every axis if `None`; one
    /// value means every axis).
    Ball {
        /// Radius.
        radius: f64,
        /// Height `a`.
        height: f64,
        /// Centre.
        centre: Option<Vec<f64>>,
        /// Whether the ball wraps around the torus where it crosses a face (`wrap`), instead
        /// of being cut there as every other integrand is.
        wrap: bool,
    },
    /// A Gaussian of width `sigma` and height `height`.
    Gaussian {
        /// Width σ.
        sigma: f64,
        /// Height `a`.
        height: f64,
        /// Centre.
        centre: Option<Vec<f64>>,
    },
    /// A function tabulated in a file (2D).
    Grid {
        /// The text, PNG or `.npy` file.
        path: PathBuf,
        /// The factor every value is multiplied by (`a=`: a PNG's grey levels in `[0, 1]` to
        /// radiance, say).
        scale: f64,
        /// What the cells are (`,exact`, `,samples`; by default a finer function's averages
        /// over them).
        meaning: GridMeaning,
    },
    /// A polygon of height 1 on these vertices (2D).
    Polygon {
        /// The vertices, in either orientation.
        vertices: Vec<[f64; 2]>,
    },
    /// An anisotropic Gaussian (2D; see [`super::AnisotropicGaussian`]).
    AnisotropicGaussian {
        /// Width along the direction at `angle`.
        sigma_1: f64,
        /// Width across it.
        sigma_2: f64,
        /// The direction, in degrees.
        angle: f64,
        /// Height `a`.
        height: f64,
        /// Centre (0.5 on both axes if `None`).
        centre: Option<Vec<f64>>,
    },
    /// An edge: the half-plane `n·x ≤ t` clipped to the square (2D; see
    /// [`super::Polygon::edge`]).
    Edge {
        /// The normal's angle `θ`, in degrees.
        theta: f64,
        /// The line's place, as a fraction of the square's extent along the normal.
        offset: f64,
        /// Height `a`.
        height: f64,
    },
}

/// Every form [`parse_integrand`] accepts, in words: the one list the command line's help and
/// the parser's errors both show.
pub const INTEGRAND_FORMS: &str = "disk, ball or gaussian, with optional overrides such as \
                                   disk:r=0.2,a=2 (cut at the faces; disk:c=0.9;0.5,wrap wraps it around the torus), grid:FILE for a text, PNG, OpenEXR or .npy grid of a finer function's cell averages (grid:FILE,a=0.14 scales it; ,samples for values at the centres, ,exact for a grid that is the function), \
                                   polygon:x,y;x,y;x,y or polygon:@FILE, \
                                   edge:theta=30,offset=0.5, or agaussian:s1=0.05,s2=0.02,angle=30";

/// The disk (`disk`: radius 0.25 at the centre, height 1), the integrand the command line uses
/// when none is named.
impl Default for IntegrandSpec {
    fn default() -> Self {
        IntegrandSpec::Ball {
            radius: 0.25,
            height: 1.0,
            centre: None,
            wrap: false,
        }
    }
}

/// Parses an integrand specification.
///
/// # Errors
/// An unknown kind, an unknown or repeated key, a key that does not fit the kind, or a value
/// that is not a number; the message lists the accepted keys.
///
/// # Examples
/// ```
/// use specvar::integrand::{parse_integrand, Integrand, IntegrandKind};
/// let spec = parse_integrand("disk:r=0.2,a=2").unwrap();
/// assert_eq!(spec.kind(), IntegrandKind::Ball);
/// let disk = spec.build(2).unwrap();
/// assert!((disk.integral() - 2.0 * std::f64::consts::PI * 0.04).abs() < 1e-12);
/// assert!(parse_integrand("disk:radius=0.2").is_err());
/// assert!(parse_integrand("disk:r=0.1,r=0.2").is_err()); // a key appears once
/// assert!(parse_integrand("cube").is_err());
/// ```
pub fn parse_integrand(text: &str) -> Result<IntegrandSpec> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    match kind.trim() {
        "disk" | "ball" => {
            // `wrap` is a word, not a key: the ball wrapped around the torus.
            let wrap = rest.split(',').any(|p| p.trim() == "wrap");
            let keys: Vec<&str> = rest.split(',').filter(|p| p.trim() != "wrap").collect();
            let v = KeyValues::parse("disk", &keys.join(","), BALL_KEYS)?;
            Ok(IntegrandSpec::Ball {
                radius: v.one("r").unwrap_or(0.25),
                height: v.one("a").unwrap_or(1.0),
                centre: v.list("c"),
                wrap,
            })
        }
        "gaussian" => {
            let v = KeyValues::parse("gaussian", rest, GAUSSIAN_KEYS)?;
            Ok(IntegrandSpec::Gaussian {
                sigma: v.one("sigma").unwrap_or(0.1),
                height: v.one("a").unwrap_or(1.0),
                centre: v.list("c"),
            })
        }
        "edge" => {
            let v = KeyValues::parse("edge", rest, EDGE_KEYS)?;
            Ok(IntegrandSpec::Edge {
                theta: v.one("theta").unwrap_or(0.0),
                offset: v.one("offset").unwrap_or(0.5),
                height: v.one("a").unwrap_or(1.0),
            })
        }
        "agaussian" => {
            let v = KeyValues::parse("agaussian", rest, ANISOTROPIC_KEYS)?;
            Ok(IntegrandSpec::AnisotropicGaussian {
                sigma_1: v.one("s1").unwrap_or(0.05),
                sigma_2: v.one("s2").unwrap_or(0.02),
                angle: v.one("angle").unwrap_or(0.0),
                height: v.one("a").unwrap_or(1.0),
                centre: v.list("c"),
            })
        }
        "grid" | "image" if rest.trim().is_empty() => {
            Err(invalid("integrand", text, "grid:FILE with a file name"))
        }
        "grid" | "image" => parse_grid(rest),
        "polygon" => parse_polygon(rest),
        other => Err(invalid("integrand", other, INTEGRAND_FORMS)),
    }
}

/// `FILE`, then optionally `,a=SCALE` and one of `,averages` (the default), `,samples` or
/// `,exact` ([`GridMeaning`]), in either order: a trailing part that is one of these is taken as
/// it, anything else is part of the file name.
fn parse_grid(rest: &str) -> Result<IntegrandSpec> {
    let mut path = rest.trim();
    let (mut scale, mut meaning) = (None, None);
    while let Some((head, tail)) = path.rsplit_once(',') {
        let word = tail.trim();
        let as_meaning = word.parse::<GridMeaning>().ok();
        if let (Some(m), None) = (as_meaning, meaning) {
            meaning = Some(m);
        } else if let (Some(value), None) = (word.strip_prefix("a="), scale) {
            match value.trim().parse::<f64>() {
                Ok(a) if a.is_finite() && a != 0.0 => scale = Some(a),
                _ => {
                    return Err(invalid(
                        "grid scale",
                        crate::error::quoted(value),
                        "a finite non-zero number, as in grid:FILE,a=0.14",
                    ))
                }
            }
        } else {
            break;
        }
        path = head;
    }
    if path.is_empty() {
        return Err(invalid(
            "grid file",
            "''",
            "a file name, as in grid:FILE,exact",
        ));
    }
    Ok(IntegrandSpec::Grid {
        path: path.into(),
        scale: scale.unwrap_or(1.0),
        meaning: meaning.unwrap_or(GridMeaning::CellAverages),
    })
}

/// A key of the `name:key=value,…` grammar: its name, what it sets, and whether it takes a
/// list of numbers separated by `;` (a centre) or one number.
struct Key {
    name: &'static str,
    what: &'static str,
    list: bool,
}

const HEIGHT: Key = Key {
    name: "a",
    what: "height",
    list: false,
};
const CENTRE: Key = Key {
    name: "c",
    what: "centre, one value or d values separated by ';'",
    list: true,
};
const BALL_KEYS: &[Key] = &[
    Key {
        name: "r",
        what: "radius",
        list: false,
    },
    HEIGHT,
    CENTRE,
];
const GAUSSIAN_KEYS: &[Key] = &[
    Key {
        name: "sigma",
        what: "width",
        list: false,
    },
    HEIGHT,
    CENTRE,
];
const EDGE_KEYS: &[Key] = &[
    Key {
        name: "theta",
        what: "the normal's angle in degrees",
        list: false,
    },
    Key {
        name: "offset",
        what: "fraction in (0, 1)",
        list: false,
    },
    HEIGHT,
];
const ANISOTROPIC_KEYS: &[Key] = &[
    Key {
        name: "s1",
        what: "width along the angle",
        list: false,
    },
    Key {
        name: "s2",
        what: "width across",
        list: false,
    },
    Key {
        name: "angle",
        what: "degrees",
        list: false,
    },
    HEIGHT,
    Key {
        name: "c",
        what: "centre x;y",
        list: true,
    },
];

/// The values of a `key=value,…` list, each key at most once and among the form's keys.
struct KeyValues(Vec<(&'static str, Vec<f64>)>);

impl KeyValues {
    /// Parses `rest` against `keys`; errors list the accepted keys.
    fn parse(form: &str, rest: &str, keys: &'static [Key]) -> Result<Self> {
        let accepted = || {
            let list: Vec<String> = keys
                .iter()
                .map(|k| format!("{} ({})", k.name, k.what))
                .collect();
            format!("accepted keys for {form}: {}, each once", list.join(", "))
        };
        let mut values: Vec<(&'static str, Vec<f64>)> = Vec::new();
        for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let (name, value) = pair
                .split_once('=')
                .ok_or_else(|| invalid("integrand override", pair, accepted()))?;
            let name = name.trim();
            let key = keys.iter().find(|k| k.name == name).ok_or_else(|| {
                invalid("integrand key", format!("{name} (for {form})"), accepted())
            })?;
            if values.iter().any(|(k, _)| *k == key.name) {
                return Err(invalid(
                    "integrand key",
                    format!("{name} given twice"),
                    accepted(),
                ));
            }
            let number = |v: &str| {
                v.trim()
                    .parse::<f64>()
                    .map_err(|_| invalid("integrand value", format!("{name}={v}"), "a number"))
            };
            let parsed = match key.list {
                true => value.split(';').map(number).collect::<Result<Vec<_>>>()?,
                false => vec![number(value)?],
            };
            values.push((key.name, parsed));
        }
        Ok(Self(values))
    }

    fn list(&self, key: &str) -> Option<Vec<f64>> {
        self.0
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.clone())
    }

    fn one(&self, key: &str) -> Option<f64> {
        self.list(key).map(|v| v[0])
    }
}

/// `x,y;x,y;…`, or `@FILE` with one vertex `x y` (or `x,y`) per line.
fn parse_polygon(rest: &str) -> Result<IntegrandSpec> {
    let rest = rest.trim();
    let (text, separator) = match rest.strip_prefix('@') {
        Some(path) => {
            let bytes = crate::io::read_bounded(std::path::Path::new(path.trim()))?;
            let text = String::from_utf8(bytes)
                .map_err(|_| Error::format(path.trim().to_string(), "not UTF-8 text"))?;
            (text, '\n')
        }
        None => (rest.to_string(), ';'),
    };
    let vertices = text
        .split(separator)
        .enumerate()
        .filter(|(_, v)| !v.trim().is_empty() && !v.trim_start().starts_with('#'))
        .map(|(i, v)| {
            let values: Vec<&str> = v
                .split([',', ' ', '\t'])
                .filter(|s| !s.is_empty())
                .collect();
            let parse = |s: &str| s.trim().parse::<f64>().ok();
            match values.as_slice() {
                [x, y] => parse(x).zip(parse(y)).map(|(x, y)| [x, y]),
                _ => None,
            }
            .ok_or_else(|| Error::Parse {
                line: i + 1,
                message: format!("vertex '{}': expected two numbers x, y", v.trim()),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(IntegrandSpec::Polygon { vertices })
}

impl IntegrandSpec {
    /// The seed talk's two integrands: the disk of radius 1/4 and the Gaussian σ = 0.1, both
    /// centred, of height 1.
    pub fn talk_pair() -> Vec<IntegrandSpec> {
        vec![
            IntegrandSpec::Ball {
                radius: 0.25,
                height: 1.0,
                centre: None,
                wrap: false,
            },
            IntegrandSpec::Gaussian {
                sigma: 0.1,
                height: 1.0,
                centre: None,
            },
        ]
    }

    /// The kind.
    pub fn kind(&self) -> IntegrandKind {
        match self {
            IntegrandSpec::Ball { .. } => IntegrandKind::Ball,
            IntegrandSpec::Gaussian { .. } => IntegrandKind::Gaussian,
            IntegrandSpec::Grid { .. } => IntegrandKind::Grid,
            IntegrandSpec::Polygon { .. } | IntegrandSpec::Edge { .. } => IntegrandKind::Polygon,
            IntegrandSpec::AnisotropicGaussian { .. } => IntegrandKind::AnisotropicGaussian,
        }
    }

    /// Builds the integrand in dimension `d`.
    ///
    /// # Errors
    /// A centre of the wrong length, or invalid parameters (see [`Ball::new`],
    /// [`Gaussian::new`]); for a grid, a dimension other than 2 or an unreadable file.
    pub fn build(&self, d: usize) -> Result<Box<dyn Integrand>> {
        let centre = |c: &Option<Vec<f64>>| -> Result<Vec<f64>> {
            match c {
                None => Ok(vec![0.5; d]),
                Some(c) if c.len() == 1 => Ok(vec![c[0]; d]),
                Some(c) if c.len() == d => Ok(c.clone()),
                Some(c) => Err(invalid(
                    "centre",
                    format!("{c:?}"),
                    format!("one value or {d} values separated by ';'"),
                )),
            }
        };
        Ok(match self {
            IntegrandSpec::Grid {
                path,
                scale,
                meaning,
            } => {
                if d != 2 {
                    return Err(invalid("dimension", d, "2 for a grid integrand"));
                }
                let grid = read_grid_file(path)?.with_meaning(*meaning);
                if *scale == 1.0 {
                    Box::new(grid)
                } else {
                    Box::new(grid.scaled(*scale)?)
                }
            }
            IntegrandSpec::Polygon { .. }
            | IntegrandSpec::Edge { .. }
            | IntegrandSpec::AnisotropicGaussian { .. }
                if d != 2 =>
            {
                return Err(invalid(
                    "dimension",
                    d,
                    "2 for a polygon, an edge or an anisotropic Gaussian",
                ));
            }
            IntegrandSpec::AnisotropicGaussian {
                sigma_1,
                sigma_2,
                angle,
                height,
                centre: c,
            } => {
                let c = centre(c)?;
                Box::new(AnisotropicGaussian::new(
                    *sigma_1,
                    *sigma_2,
                    *angle,
                    [c[0], c[1]],
                    *height,
                )?)
            }
            IntegrandSpec::Polygon { vertices } => Box::new(Polygon::new(vertices.clone(), 1.0)?),
            IntegrandSpec::Edge {
                theta,
                offset,
                height,
            } => Box::new(Polygon::edge(*theta, *offset, *height)?),
            IntegrandSpec::Ball {
                radius,
                height,
                centre: c,
                wrap,
            } => {
                let ball = Ball::new(*radius, centre(c)?, *height)?;
                if *wrap || !ball.crosses_a_face() {
                    Box::new(ball)
                } else {
                    ball.cut_at_the_faces()?
                }
            }
            IntegrandSpec::Gaussian {
                sigma,
                height,
                centre: c,
            } => Box::new(Gaussian::new(*sigma, centre(c)?, *height)?),
        })
    }
}

impl FromStr for IntegrandSpec {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        parse_integrand(s)
    }
}

/// The canonical text of a specification, which [`parse_integrand`] reads back.
impl fmt::Display for IntegrandSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let centre = |c: &Option<Vec<f64>>| match c {
            None => String::new(),
            Some(c) => format!(
                ",c={}",
                c.iter()
                    .map(|v| v.to_string())
                    .collect::<Vec<_>>()
                    .join(";")
            ),
        };
        match self {
            IntegrandSpec::Ball {
                radius,
                height,
                centre: c,
                wrap,
            } => write!(
                f,
                "ball:r={radius},a={height}{}{}",
                centre(c),
                if *wrap { ",wrap" } else { "" }
            ),
            IntegrandSpec::Gaussian {
                sigma,
                height,
                centre: c,
            } => write!(f, "gaussian:sigma={sigma},a={height}{}", centre(c)),
            IntegrandSpec::Grid {
                path,
                scale,
                meaning,
            } => {
                write!(f, "grid:{}", path.display())?;
                if *scale != 1.0 {
                    write!(f, ",a={scale}")?;
                }
                if *meaning != GridMeaning::CellAverages {
                    write!(f, ",{}", meaning.name())?;
                }
                Ok(())
            }
            IntegrandSpec::Polygon { vertices } => {
                let list: Vec<String> = vertices
                    .iter()
                    .map(|v| format!("{},{}", v[0], v[1]))
                    .collect();
                write!(f, "polygon:{}", list.join(";"))
            }
            IntegrandSpec::Edge {
                theta,
                offset,
                height,
            } => write!(f, "edge:theta={theta},offset={offset},a={height}"),
            IntegrandSpec::AnisotropicGaussian {
                sigma_1,
                sigma_2,
                angle,
                height,
                centre: c,
            } => write!(
                f,
                "agaussian:s1={sigma_1},s2={sigma_2},angle={angle},a={height}{}",
                centre(c)
            ),
        }
    }
}

impl Serialize for IntegrandSpec {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.to_string())
    }
}

impl<'de> serde::Deserialize<'de> for IntegrandSpec {
    /// The text [`parse_integrand`] reads.
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}
