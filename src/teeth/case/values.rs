//! Validated values of case files: finite and non-negative numbers, tooth lists and maps without
//! duplicates. Each refuses bad input where it is read, so the error carries the file position.

use std::{collections::BTreeMap, fmt};

use serde::{
    Deserialize, Deserializer, Serialize,
    de::{self, MapAccess, SeqAccess, Visitor},
};

use crate::teeth::fdi::Fdi;

/// An f32 that must be finite (NaN and infinities are refused where they are read).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Finite(pub f32);

impl<'de> Deserialize<'de> for Finite {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = f64::deserialize(d)?;
        if !v.is_finite() || v.abs() > f32::MAX as f64 {
            return Err(de::Error::custom(format!("number must be finite, got {v}")));
        }
        Ok(Self(v as f32))
    }
}

/// A finite, non-negative f32 (sizes, limits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct NonNegative(pub f32);

impl<'de> Deserialize<'de> for NonNegative {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(v) = Finite::deserialize(d)?;
        if v < 0.0 {
            return Err(de::Error::custom(format!(
                "size must not be negative, got {v}"
            )));
        }
        Ok(Self(v))
    }
}

/// A list of distinct teeth (a duplicate is an error at its position).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct ToothList(pub Vec<Fdi>);

impl<'de> Deserialize<'de> for ToothList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ToothList;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a list of FDI tooth numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ToothList, A::Error> {
                let mut out = Vec::new();
                while let Some(t) = seq.next_element::<Fdi>()? {
                    if out.contains(&t) {
                        return Err(de::Error::custom(format!("duplicate tooth {t}")));
                    }
                    out.push(t);
                }
                Ok(ToothList(out))
            }
        }
        d.deserialize_seq(V)
    }
}

/// A map keyed by tooth whose keys must be distinct.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct ToothMap<T>(pub BTreeMap<Fdi, T>);

impl<T> ToothMap<T> {
    /// True when no tooth is listed.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<T> Default for ToothMap<T> {
    fn default() -> Self {
        Self(BTreeMap::new())
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for ToothMap<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = ToothMap<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a map from FDI tooth numbers")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ToothMap<T>, A::Error> {
                let mut out = BTreeMap::new();
                while let Some(k) = map.next_key::<Fdi>()? {
                    if out.contains_key(&k) {
                        return Err(de::Error::custom(format!("duplicate tooth {k}")));
                    }
                    let v = map.next_value::<T>()?;
                    out.insert(k, v);
                }
                Ok(ToothMap(out))
            }
        }
        d.deserialize_map(V(std::marker::PhantomData))
    }
}
