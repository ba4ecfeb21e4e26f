//! The data types of legacy VTK arrays, how binary files store them (big-endian
//! [`ScalarType`] elements, decoded by [`crate::io::elements`]), and ASCII words as `f64`
//! (data) or `i64` (cell arrays).

use crate::io::elements::{is_integer, ScalarType};

/// A legacy VTK data type name, as `vtkDataReader` accepts them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ValueType {
    /// `char`, `signed_char`: 1-byte signed.
    Char,
    /// `unsigned_char`.
    UnsignedChar,
    /// `short`.
    Short,
    /// `unsigned_short`.
    UnsignedShort,
    /// `int`.
    Int,
    /// `unsigned_int`.
    UnsignedInt,
    /// `long` (8 bytes, as VTK on 64-bit Linux reads it).
    Long,
    /// `unsigned_long` (8 bytes).
    UnsignedLong,
    /// `vtktypeint64`.
    Int64,
    /// `vtktypeuint64`.
    UnsignedInt64,
    /// `vtkIdType`: written as a 4-byte int by VTK's legacy writer.
    IdType,
    /// `float`.
    Float,
    /// `double`.
    Double,
}

impl ValueType {
    /// The type a (case-insensitive) type word names, or why it cannot be read.
    pub fn parse(word: &[u8]) -> Result<ValueType, String> {
        let lower = word.to_ascii_lowercase();
        Ok(match lower.as_slice() {
            b"char" | b"signed_char" => ValueType::Char,
            b"unsigned_char" => ValueType::UnsignedChar,
            b"short" => ValueType::Short,
            b"unsigned_short" => ValueType::UnsignedShort,
            b"int" => ValueType::Int,
            b"unsigned_int" => ValueType::UnsignedInt,
            b"long" => ValueType::Long,
            b"unsigned_long" => ValueType::UnsignedLong,
            b"vtktypeint64" => ValueType::Int64,
            b"vtktypeuint64" => ValueType::UnsignedInt64,
            b"vtkidtype" => ValueType::IdType,
            b"float" => ValueType::Float,
            b"double" => ValueType::Double,
            b"bit" => {
                return Err(
                    "'bit' values are not allowed here (only in FIELD and attribute \
                     arrays)"
                        .into(),
                )
            }
            b"string" | b"utf8_string" | b"variant" => return Err(not_numbers(word)),
            _ => return Err(format!("unknown data type '{}'", super::cursor::show(word))),
        })
    }

    /// How binary files store its values (always big-endian): `long` as 8 bytes, as VTK on
    /// 64-bit Linux reads it, and `vtkIdType` as 4, as VTK's legacy writer writes it.
    pub fn element(self) -> ScalarType {
        match self {
            ValueType::Char => ScalarType::I8,
            ValueType::UnsignedChar => ScalarType::U8,
            ValueType::Short => ScalarType::I16,
            ValueType::UnsignedShort => ScalarType::U16,
            ValueType::Int | ValueType::IdType => ScalarType::I32,
            ValueType::UnsignedInt => ScalarType::U32,
            ValueType::Long | ValueType::Int64 => ScalarType::I64,
            ValueType::UnsignedLong | ValueType::UnsignedInt64 => ScalarType::U64,
            ValueType::Float => ScalarType::F32,
            ValueType::Double => ScalarType::F64,
        }
    }

    /// Bytes per value in binary files.
    pub fn size(self) -> usize {
        self.element().size()
    }

    /// Whether values are integers (cell arrays must be).
    pub fn is_integer(self) -> bool {
        is_integer(self.element())
    }
}

/// Why strings or variants (`word` names them) cannot be read where numbers must be.
fn not_numbers(word: &[u8]) -> String {
    format!(
        "'{}' values are not numbers (only FIELD arrays and PEDIGREE_IDS hold them)",
        super::cursor::show(word)
    )
}

/// The data type of a `FIELD` or attribute array: numbers (bits among them), or values VTK
/// keeps in arrays that are not numeric (`vtkStringArray`, `vtkVariantArray`), which no mesh
/// array can take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ArrayType {
    /// Numbers of a [`ValueType`].
    Number(ValueType),
    /// `bit` (a `vtkBitArray`, a numeric array to VTK, which reads it as values 0 and 1): a
    /// binary file packs eight values a byte, the first in the high bit; an ASCII file gives
    /// one integer a value, any but 0 meaning 1.
    Bit,
    /// `string` (and `utf8_string`, as VTK before 9.2 wrote `vtkUnicodeStringArray`s, which
    /// VTK 9.1 still reads): a binary file gives each value as a length header (its first
    /// byte's two high bits say how many bytes it has) and that many bytes; an ASCII file one
    /// line a value, `%XX`-escaped.
    String,
    /// `variant`: each value a VTK type code and a `%XX`-escaped word, as text in both
    /// encodings.
    Variant,
}

impl ArrayType {
    /// The type a (case-insensitive) type word names, or why it cannot be read.
    pub fn parse(word: &[u8]) -> Result<ArrayType, String> {
        match word.to_ascii_lowercase().as_slice() {
            b"bit" => Ok(ArrayType::Bit),
            b"string" | b"utf8_string" => Ok(ArrayType::String),
            b"variant" => Ok(ArrayType::Variant),
            _ => ValueType::parse(word).map(ArrayType::Number),
        }
    }

    /// The type of an attribute that holds numbers (`SCALARS`, `VECTORS`, …): numbers or bits.
    pub fn parse_numeric(word: &[u8]) -> Result<ArrayType, String> {
        match ArrayType::parse(word)? {
            ArrayType::String | ArrayType::Variant => Err(not_numbers(word)),
            numeric => Ok(numeric),
        }
    }
}

/// An ASCII number as `f64` (`nan` and `inf` included, as C's `strtod` reads them).
pub(super) fn parse_f64(word: &[u8]) -> Option<f64> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

/// An ASCII integer as `i64` (optional sign, decimal digits only).
pub(super) fn parse_i64(word: &[u8]) -> Option<i64> {
    let (negative, digits) = match word.first()? {
        b'-' => (true, &word[1..]),
        b'+' => (false, &word[1..]),
        _ => (false, word),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d - b'0'))?;
    }
    Some(if negative { -value } else { value })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_and_sizes() {
        assert_eq!(ValueType::parse(b"FLOAT"), Ok(ValueType::Float));
        assert_eq!(ValueType::parse(b"vtkIdType").map(ValueType::size), Ok(4));
        assert_eq!(
            ValueType::parse(b"vtktypeuint64").map(ValueType::size),
            Ok(8)
        );
        assert!(ValueType::parse(b"bit")
            .unwrap_err()
            .contains("not allowed here"));
        assert!(ValueType::parse(b"quaternion")
            .unwrap_err()
            .contains("unknown"));
        // Strings and variants: FIELD arrays and pedigree ids may hold them, nothing else.
        assert!(ValueType::parse(b"string")
            .unwrap_err()
            .contains("not numbers"));
        assert_eq!(ArrayType::parse(b"STRING"), Ok(ArrayType::String));
        assert_eq!(ArrayType::parse(b"utf8_string"), Ok(ArrayType::String));
        assert_eq!(ArrayType::parse(b"variant"), Ok(ArrayType::Variant));
        assert_eq!(ArrayType::parse(b"Bit"), Ok(ArrayType::Bit));
        assert_eq!(ArrayType::parse_numeric(b"bit"), Ok(ArrayType::Bit));
        assert!(ArrayType::parse_numeric(b"string")
            .unwrap_err()
            .contains("not numbers"));
        assert_eq!(
            ArrayType::parse(b"double"),
            Ok(ArrayType::Number(ValueType::Double))
        );
    }

    /// Binary files store each type as VTK's legacy writer and reader do.
    #[test]
    fn stored_elements() {
        assert_eq!(ValueType::IdType.element(), ScalarType::I32);
        assert_eq!(ValueType::Long.element(), ScalarType::I64);
        assert_eq!(ValueType::UnsignedLong.element(), ScalarType::U64);
        assert_eq!(ValueType::Float.element(), ScalarType::F32);
        assert!(ValueType::UnsignedChar.is_integer() && !ValueType::Double.is_integer());
    }

    #[test]
    fn ascii_numbers() {
        assert_eq!(parse_i64(b"-42"), Some(-42));
        assert_eq!(parse_i64(b"+7"), Some(7));
        assert_eq!(parse_i64(b"1.0"), None);
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b"99999999999999999999"), None);
        assert_eq!(parse_f64(b"1e-3"), Some(1e-3));
        assert!(parse_f64(b"nan").is_some_and(f64::is_nan));
        assert_eq!(parse_f64(b"x"), None);
    }
}
