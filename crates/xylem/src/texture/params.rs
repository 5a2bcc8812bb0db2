//! Named texture parameters: each texture declares its parameters (default and allowed range);
//! user values are checked against the declaration, so every error names the texture, the
//! parameter and what is allowed.

use std::collections::BTreeMap;

/// One parameter a texture accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// The name in `params = { name = value }`.
    pub name: &'static str,
    /// Value when the user gives none.
    pub default: f32,
    /// Smallest allowed value.
    pub min: f32,
    /// Largest allowed value.
    pub max: f32,
    /// One line: what it does and its unit.
    pub doc: &'static str,
}

/// Shorthand for the declaration tables.
pub(crate) const fn p(
    name: &'static str,
    default: f32,
    min: f32,
    max: f32,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        name,
        default,
        min,
        max,
        doc,
    }
}

/// Errors of [`super::by_name`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TextureError {
    /// No texture of this name.
    #[error("unknown texture `{name}`; valid names: {valid}")]
    UnknownTexture {
        /// The name given.
        name: String,
        /// The valid names.
        valid: String,
    },
    /// The texture has no parameter of this name.
    #[error("texture `{texture}` has no parameter `{param}`; allowed: {allowed}")]
    UnknownParam {
        /// The texture.
        texture: String,
        /// The parameter given.
        param: String,
        /// The texture's parameter names.
        allowed: String,
    },
    /// A parameter value outside its declared range (or not finite).
    #[error("texture `{texture}`: parameter `{param}` = {value} is outside [{min}, {max}]")]
    OutOfRange {
        /// The texture.
        texture: String,
        /// The parameter.
        param: String,
        /// The value given.
        value: f32,
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
    /// The texture's noise basis rejected its parameters.
    #[error("texture `{texture}`: {source}")]
    Noise {
        /// The texture.
        texture: String,
        /// The noise error.
        source: crate::noise::NoiseError,
    },
}

/// Parameter values after checking: every declared parameter has a value.
#[derive(Clone, Debug)]
pub struct Values {
    values: BTreeMap<&'static str, f32>,
}

impl Values {
    /// Checks `given` against `spec` for texture `texture`.
    pub fn resolve(
        texture: &str,
        spec: &[ParamSpec],
        given: &BTreeMap<String, f32>,
    ) -> Result<Values, TextureError> {
        for key in given.keys() {
            if !spec.iter().any(|s| s.name == key) {
                return Err(TextureError::UnknownParam {
                    texture: texture.to_string(),
                    param: key.clone(),
                    allowed: spec.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
                });
            }
        }
        let mut values = BTreeMap::new();
        for s in spec {
            let v = given.get(s.name).copied().unwrap_or(s.default);
            if !(v >= s.min && v <= s.max) {
                return Err(TextureError::OutOfRange {
                    texture: texture.to_string(),
                    param: s.name.to_string(),
                    value: v,
                    min: s.min,
                    max: s.max,
                });
            }
            values.insert(s.name, v);
        }
        Ok(Values { values })
    }

    /// The value of a declared parameter (panics only on a typo in a declaration table, which
    /// the tests exercise for every texture).
    pub fn get(&self, name: &str) -> f32 {
        self.values[name]
    }

    /// An integer-valued parameter (octaves, modes), rounded.
    pub fn int(&self, name: &str) -> u32 {
        self.get(name).round() as u32
    }

    /// The seed parameter as an integer.
    pub fn seed(&self) -> u32 {
        self.int("seed")
    }
}
