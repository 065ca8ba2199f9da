//! Parameters declared once. A mode's parameters are one [`declare_params!`] block: each field
//! with its type, default, canonical key and — for the mode's own keys — its [`ParamSpec`]
//! (name, kind and range, scope, help). From that block come the struct and its `Default`, the
//! spec constants and the mode's spec list, reading a request or a texture's table, the values
//! `/textures/{id}` describes, the text each value reads back from, and the canonical text that
//! keys the caches and ETags. The server's parsing, metadata, OpenAPI document, CLI
//! `--list-params` and the viewer's panel all read the specs; nothing else lists a parameter.
//!
//! Why a `macro_rules!` block and not a derive: a derive needs a proc-macro crate of its own
//! (a third crate to build and keep in step for four structs), and the canonical key of each
//! field must stay exactly what it was (clients keep tiles a year under those ETags), which a
//! declaration states plainly next to the field. The `canonical` part of a field is its
//! prefix in the canonical text (`";it="`), `none` for a field that does not change the pixels
//! (the tiling's seed), or `(unless_default ";controls=")` for one added only when set, so that
//! older keys stay as they were.
//!
//! A field is read either from the common keys (`seed`, `period` from `world`) or from its own
//! spec (`spec NAME = "key", KIND, SCOPE, "help"`); its type says how its text is read and
//! written ([`ParamValue`]).

use serde_json::{json, Value};

#[doc(hidden)]
pub use serde_json;

use super::params::{parse_unit, Kind, ParamSpec, ONE_Q16};
use crate::error::Result;

/// The canonical text of a value: what keys caches and ETags (fixed point, no float noise).
pub trait Canonical {
    /// Canonical text.
    fn canonical(&self) -> String;
}

/// A parameter value read from text through its spec: parsed, described as JSON, written back
/// as text that reads to the same value, and canonical.
pub trait ParamValue: Canonical + Sized {
    /// Parse the text given for `spec`.
    fn parse(spec: &ParamSpec, s: &str) -> Result<Self>;
    /// As JSON, for descriptions (`levels`: the exemplar's finest synthesis level `L`).
    fn json(&self, spec: &ParamSpec, levels: u32) -> Value;
    /// As text that [`ParamValue::parse`] reads back to this value.
    fn text(&self, spec: &ParamSpec) -> String;
}

/// A fixed-point value in `[0, 1]` as a short decimal (4 places: no float noise), for
/// descriptions.
pub fn unit_value(v: u32) -> f64 {
    (v as f64 / ONE_Q16 as f64 * 10_000.0).round() / 10_000.0
}

/// A fixed-point value in `[0, 1]` as text that reads back to it exactly (6 places: finer than
/// half a step of 2^-16).
pub fn unit_text(v: u32) -> String {
    let s = format!("{:.6}", v as f64 / ONE_Q16 as f64);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

impl Canonical for u64 {
    fn canonical(&self) -> String {
        self.to_string()
    }
}

impl ParamValue for u64 {
    fn parse(spec: &ParamSpec, s: &str) -> Result<Self> {
        spec.integer(s)
    }
    fn json(&self, _: &ParamSpec, _: u32) -> Value {
        json!(self)
    }
    fn text(&self, _: &ParamSpec) -> String {
        self.to_string()
    }
}

impl Canonical for u32 {
    fn canonical(&self) -> String {
        self.to_string()
    }
}

/// A `u32` is an integer of its spec's range, or a [`Kind::Unit`] value in fixed point.
impl ParamValue for u32 {
    fn parse(spec: &ParamSpec, s: &str) -> Result<Self> {
        match spec.kind {
            Kind::Unit => parse_unit(spec.name, s),
            _ => {
                let v = spec.integer(s)?;
                u32::try_from(v).map_err(|_| spec.error(format!("{v} is too large")))
            }
        }
    }
    fn json(&self, spec: &ParamSpec, _: u32) -> Value {
        match spec.kind {
            Kind::Unit => json!(unit_value(*self)),
            _ => json!(self),
        }
    }
    fn text(&self, spec: &ParamSpec) -> String {
        match spec.kind {
            Kind::Unit => unit_text(*self),
            _ => self.to_string(),
        }
    }
}

/// An interval `LOW,HIGH` in thousandths ([`Kind::Interval`]).
impl Canonical for (u32, u32) {
    fn canonical(&self) -> String {
        format!("{},{}", self.0, self.1)
    }
}

impl ParamValue for (u32, u32) {
    fn parse(spec: &ParamSpec, s: &str) -> Result<Self> {
        spec.interval_milli(s)
    }
    fn json(&self, _: &ParamSpec, _: u32) -> Value {
        json!([self.0 as f64 / 1000.0, self.1 as f64 / 1000.0])
    }
    fn text(&self, _: &ParamSpec) -> String {
        format!("{},{}", self.0 as f64 / 1000.0, self.1 as f64 / 1000.0)
    }
}

/// A period in texels, or none.
impl Canonical for Option<i64> {
    fn canonical(&self) -> String {
        self.map(|p| p.to_string()).unwrap_or_else(|| "none".into())
    }
}

/// A closed set of words ([`Kind::Choice`]): each value's name, in the order of
/// [`Choice::NAMES`].
pub trait Choice: Copy + Sized + 'static {
    /// The words, as the API spells them.
    const NAMES: &'static [&'static str];
    /// Every value, in the order of [`Choice::NAMES`].
    const ALL: &'static [Self];
    /// Its position in [`Choice::ALL`].
    fn index(self) -> usize;
    /// Its word.
    fn name(self) -> &'static str {
        Self::NAMES[self.index()]
    }
}

impl<C: Choice> Canonical for C {
    fn canonical(&self) -> String {
        self.name().to_string()
    }
}

impl<C: Choice> ParamValue for C {
    fn parse(spec: &ParamSpec, s: &str) -> Result<Self> {
        spec.check(s)?;
        let i = C::NAMES.iter().position(|n| *n == s).ok_or_else(|| spec.error(format!("'{s}' is not a choice")))?;
        Ok(C::ALL[i])
    }
    fn json(&self, _: &ParamSpec, _: u32) -> Value {
        json!(self.name())
    }
    fn text(&self, _: &ParamSpec) -> String {
        self.name().to_string()
    }
}

/// A mode's parameters as [`declare_params!`] declares them: everything the front ends and the
/// caches need to know of them, generated from one declaration.
pub trait Declared: Clone + std::fmt::Debug + PartialEq + Eq + std::hash::Hash + Send + Sync + 'static {
    /// The mode's own parameters, in declaration order (the common ones are
    /// [`super::params::COMMON`]).
    const SPECS: &'static [ParamSpec];
    /// Read the declared keys from `r` over `self`, apply `common`, and check the result for
    /// `src`.
    fn parse(
        &self,
        common: &super::params::Common,
        r: &mut super::params::ParamReader,
        src: &super::Source,
    ) -> Result<Self>;
    /// The current value of each spec'd field (and `seed`) as JSON, for descriptions.
    fn values(&self, src: &super::Source) -> serde_json::Map<String, Value>;
    /// Canonical text of every field that determines the pixels, for cache keys and ETags.
    fn canonical(&self) -> String;
    /// Every spec'd field (and `seed`) as `(key, text)`: read back over any parameters, they
    /// give these.
    fn texts(&self) -> Vec<(&'static str, String)>;
}

/// Declare a mode's parameters once (see the module documentation of `modes::declared`):
///
/// ```ignore
/// declare_params! {
///     /// Validated mosaic parameters.
///     pub struct MosaicParams {
///         /// Selects another arrangement of blocks.
///         pub seed: u64 { default: 0, canonical: "seed=", seed }
///         /// Cat-map iterations.
///         pub iterations: u32 { default: 10, canonical: ";it=",
///             spec ITERATIONS = "iterations", Kind::Integer { min: 0, max: 64 }, Request, "help" }
///         pub period: Option<i64> { default: None, canonical: ";period=", period }
///     }
///     check(p, src) { p.validate(src.exemplar.size().longer()) }
/// }
/// ```
#[macro_export]
macro_rules! declare_params {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[$fmeta:meta])*
                $fvis:vis $field:ident : $fty:ty { $($body:tt)* }
            )+
        }
        check($p:ident, $src:ident) $check:block
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Eq, Hash)]
        $vis struct $name {
            $( $(#[$fmeta])* $fvis $field: $fty, )+
        }

        impl Default for $name {
            fn default() -> Self {
                $name { $( $field: $crate::declare_params!(@default $($body)*), )+ }
            }
        }

        $( $crate::declare_params!(@spec_const $($body)*); )+

        impl $crate::modes::declared::Declared for $name {
            const SPECS: &'static [$crate::modes::params::ParamSpec] =
                $crate::declare_params!(@specs [] $({ $($body)* })+);

            fn parse(
                &self,
                common: &$crate::modes::params::Common,
                r: &mut $crate::modes::params::ParamReader,
                src: &$crate::modes::Source,
            ) -> $crate::error::Result<Self> {
                #[allow(unused_variables)]
                let (r_, common_) = (r, common);
                let mut out = self.clone();
                $( $crate::declare_params!(@read out.$field, r_, common_, $($body)*); )+
                fn check($p: &$name, $src: &$crate::modes::Source) -> $crate::error::Result<()> $check
                check(&out, src)?;
                Ok(out)
            }

            fn values(&self, src: &$crate::modes::Source) -> $crate::modes::declared::serde_json::Map<String, $crate::modes::declared::serde_json::Value> {
                #[allow(unused_mut)]
                let mut m = $crate::modes::declared::serde_json::Map::new();
                let _levels = src.levels();
                $( $crate::declare_params!(@value m, self.$field, _levels, $($body)*); )+
                m
            }

            fn canonical(&self) -> String {
                #[allow(unused_mut)]
                let mut s = String::new();
                $( $crate::declare_params!(@canon s, self.$field, $($body)*); )+
                s
            }

            #[allow(clippy::vec_init_then_push)]
            fn texts(&self) -> Vec<(&'static str, String)> {
                #[allow(unused_mut)]
                let mut t = Vec::new();
                $( $crate::declare_params!(@text t, self.$field, $($body)*); )+
                t
            }
        }
    };

    (@default default: $d:expr, $($rest:tt)*) => { $d };

    (@spec_const default: $d:expr, canonical: $c:tt, seed) => {};
    (@spec_const default: $d:expr, canonical: $c:tt, period) => {};
    (@spec_const default: $d:expr, canonical: $c:tt,
        spec $spec:ident = $key:literal, $kind:expr, $scope:ident, $help:literal) => {
        #[doc = concat!("`", $key, "`: ", $help, ".")]
        pub const $spec: $crate::modes::params::ParamSpec = $crate::modes::params::ParamSpec {
            name: $key,
            kind: $kind,
            scope: $crate::modes::params::Scope::$scope,
            help: $help,
        };
    };

    (@specs [$($acc:ident),*]) => { &[$($acc),*] };
    (@specs [$($acc:ident),*] { default: $d:expr, canonical: $c:tt, seed } $($more:tt)*) => {
        $crate::declare_params!(@specs [$($acc),*] $($more)*)
    };
    (@specs [$($acc:ident),*] { default: $d:expr, canonical: $c:tt, period } $($more:tt)*) => {
        $crate::declare_params!(@specs [$($acc),*] $($more)*)
    };
    (@specs [$($acc:ident),*] { default: $d:expr, canonical: $c:tt, spec $spec:ident = $($r:tt)* } $($more:tt)*) => {
        $crate::declare_params!(@specs [$($acc,)* $spec] $($more)*)
    };

    (@read $f:expr, $r:ident, $common:ident, default: $d:expr, canonical: $c:tt, seed) => {
        if let Some(s) = $common.seed {
            $f = s;
        }
    };
    (@read $f:expr, $r:ident, $common:ident, default: $d:expr, canonical: $c:tt, period) => {
        $f = $common.period;
    };
    (@read $f:expr, $r:ident, $common:ident, default: $d:expr, canonical: $c:tt, spec $spec:ident = $($rest:tt)*) => {
        if let Some(s) = $r.get(&$spec) {
            $f = $crate::modes::declared::ParamValue::parse(&$spec, &s)?;
        }
    };

    (@value $m:ident, $f:expr, $l:ident, default: $d:expr, canonical: $c:tt, seed) => {
        $m.insert("seed".into(), $crate::modes::declared::serde_json::json!($f));
    };
    (@value $m:ident, $f:expr, $l:ident, default: $d:expr, canonical: $c:tt, period) => {};
    (@value $m:ident, $f:expr, $l:ident, default: $d:expr, canonical: $c:tt, spec $spec:ident = $($rest:tt)*) => {
        $m.insert($spec.name.into(), $crate::modes::declared::ParamValue::json(&$f, &$spec, $l));
    };

    (@canon $s:ident, $f:expr, default: $d:expr, canonical: none, $($rest:tt)*) => {};
    (@canon $s:ident, $f:expr, default: $d:expr, canonical: (unless_default $c:literal), $($rest:tt)*) => {
        if $f != $d {
            $s.push_str($c);
            $s.push_str(&$crate::modes::declared::Canonical::canonical(&$f));
        }
    };
    (@canon $s:ident, $f:expr, default: $d:expr, canonical: $c:literal, $($rest:tt)*) => {
        $s.push_str($c);
        $s.push_str(&$crate::modes::declared::Canonical::canonical(&$f));
    };

    (@text $t:ident, $f:expr, default: $d:expr, canonical: $c:tt, seed) => {
        $t.push(("seed", $f.to_string()));
    };
    (@text $t:ident, $f:expr, default: $d:expr, canonical: $c:tt, period) => {};
    (@text $t:ident, $f:expr, default: $d:expr, canonical: $c:tt, spec $spec:ident = $($rest:tt)*) => {
        $t.push(($spec.name, $crate::modes::declared::ParamValue::text(&$f, &$spec)));
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_text_reads_back_exactly() {
        for v in [0, 1, 2, 19660, 32768, 65535, 65536] {
            assert_eq!(parse_unit("x", &unit_text(v)).unwrap(), v, "{}", unit_text(v));
        }
        assert_eq!(unit_text(32768), "0.5");
        assert_eq!(unit_text(0), "0");
        assert_eq!(unit_text(65536), "1");
    }
}
