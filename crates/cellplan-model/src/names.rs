//! The serde name of a unit enum variant, so that `Display` spells a strategy or kind exactly as
//! the cell file, the plan document and the command line do: the names are written once, in
//! the enum's `#[serde(rename_all = ...)]` (and any `#[serde(rename)]`).
use serde::Serialize;
use serde::ser::{self, Impossible};
use std::fmt;

/// The serde name of `value`, a unit variant of an enum deriving `Serialize`, e.g.
/// `"local-robust"` for `Allocation::LocalRobust` under `rename_all = "kebab-case"`.
///
/// # Panics
/// If `value` does not serialize as a unit variant (a programming error: each enum that uses
/// this has a test over all its variants).
pub fn serde_name<T: Serialize + ?Sized>(value: &T) -> &'static str {
    match value.serialize(VariantName) {
        Ok(name) => name,
        Err(NotUnitVariant) => panic!("serde_name: {} is not a unit variant", std::any::type_name::<T>()),
    }
}

/// A serializer that accepts only a unit variant and returns its name.
struct VariantName;

/// What [`VariantName`] refuses: anything but a unit variant.
#[derive(Debug)]
struct NotUnitVariant;

impl fmt::Display for NotUnitVariant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not a unit variant")
    }
}

impl std::error::Error for NotUnitVariant {}

impl ser::Error for NotUnitVariant {
    fn custom<M: fmt::Display>(_: M) -> Self {
        NotUnitVariant
    }
}

/// Serializer methods that refuse their value.
macro_rules! refuse {
    ($($method:ident($($arg:ty),*) -> $ok:ty;)*) => {
        $(fn $method(self, $(_: $arg),*) -> Result<$ok, NotUnitVariant> {
            Err(NotUnitVariant)
        })*
    };
}

type Refused = Impossible<&'static str, NotUnitVariant>;

impl ser::Serializer for VariantName {
    type Ok = &'static str;
    type Error = NotUnitVariant;
    type SerializeSeq = Refused;
    type SerializeTuple = Refused;
    type SerializeTupleStruct = Refused;
    type SerializeTupleVariant = Refused;
    type SerializeMap = Refused;
    type SerializeStruct = Refused;
    type SerializeStructVariant = Refused;

    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<&'static str, NotUnitVariant> {
        Ok(variant)
    }

    refuse! {
        serialize_bool(bool) -> &'static str;
        serialize_i8(i8) -> &'static str;
        serialize_i16(i16) -> &'static str;
        serialize_i32(i32) -> &'static str;
        serialize_i64(i64) -> &'static str;
        serialize_u8(u8) -> &'static str;
        serialize_u16(u16) -> &'static str;
        serialize_u32(u32) -> &'static str;
        serialize_u64(u64) -> &'static str;
        serialize_f32(f32) -> &'static str;
        serialize_f64(f64) -> &'static str;
        serialize_char(char) -> &'static str;
        serialize_str(&str) -> &'static str;
        serialize_bytes(&[u8]) -> &'static str;
        serialize_none() -> &'static str;
        serialize_unit() -> &'static str;
        serialize_unit_struct(&'static str) -> &'static str;
        serialize_seq(Option<usize>) -> Refused;
        serialize_tuple(usize) -> Refused;
        serialize_tuple_struct(&'static str, usize) -> Refused;
        serialize_tuple_variant(&'static str, u32, &'static str, usize) -> Refused;
        serialize_map(Option<usize>) -> Refused;
        serialize_struct(&'static str, usize) -> Refused;
        serialize_struct_variant(&'static str, u32, &'static str, usize) -> Refused;
    }

    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<&'static str, NotUnitVariant> {
        Err(NotUnitVariant)
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotUnitVariant> {
        Err(NotUnitVariant)
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotUnitVariant> {
        Err(NotUnitVariant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    #[serde(rename_all = "kebab-case")]
    enum Kind {
        LocalRobust,
        #[serde(rename = "other_name")]
        Renamed,
        #[allow(dead_code)]
        WithData(u8),
    }

    #[test]
    fn names_unit_variants_as_serde_does() {
        assert_eq!(serde_name(&Kind::LocalRobust), "local-robust");
        assert_eq!(serde_name(&Kind::Renamed), "other_name");
    }

    #[test]
    #[should_panic(expected = "not a unit variant")]
    fn refuses_other_values() {
        serde_name(&Kind::WithData(1));
    }
}
