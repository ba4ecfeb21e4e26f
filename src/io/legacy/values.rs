//! The data types of legacy VTK arrays and the decoding of their values: big-endian binary
//! blocks and ASCII words, into `f64` (data) or `i64` (cell arrays).

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
            b"bit" | b"string" | b"utf8_string" | b"variant" => {
                return Err(format!(
                    "'{}' arrays are not supported",
                    super::cursor::show(word)
                ))
            }
            _ => return Err(format!("unknown data type '{}'", super::cursor::show(word))),
        })
    }

    /// Bytes per value in binary files.
    pub fn size(self) -> usize {
        match self {
            ValueType::Char | ValueType::UnsignedChar => 1,
            ValueType::Short | ValueType::UnsignedShort => 2,
            ValueType::Int | ValueType::UnsignedInt | ValueType::IdType | ValueType::Float => 4,
            ValueType::Long
            | ValueType::UnsignedLong
            | ValueType::Int64
            | ValueType::UnsignedInt64
            | ValueType::Double => 8,
        }
    }

    /// Whether values are integers (cell arrays must be).
    pub fn is_integer(self) -> bool {
        !matches!(self, ValueType::Float | ValueType::Double)
    }
}

fn array<const N: usize>(chunk: &[u8]) -> [u8; N] {
    chunk.try_into().unwrap_or([0; N])
}

/// Appends the big-endian values of `block` (a whole number of values) as `f64`.
pub(super) fn decode_f64(ty: ValueType, block: &[u8], out: &mut Vec<f64>) {
    macro_rules! go {
        ($t:ty, $n:expr) => {
            out.extend(
                block
                    .chunks_exact($n)
                    .map(|c| <$t>::from_be_bytes(array::<$n>(c)) as f64),
            )
        };
    }
    match ty {
        ValueType::Char => go!(i8, 1),
        ValueType::UnsignedChar => go!(u8, 1),
        ValueType::Short => go!(i16, 2),
        ValueType::UnsignedShort => go!(u16, 2),
        ValueType::Int | ValueType::IdType => go!(i32, 4),
        ValueType::UnsignedInt => go!(u32, 4),
        ValueType::Long | ValueType::Int64 => go!(i64, 8),
        ValueType::UnsignedLong | ValueType::UnsignedInt64 => go!(u64, 8),
        ValueType::Float => go!(f32, 4),
        ValueType::Double => go!(f64, 8),
    }
}

/// Appends the big-endian integer values of `block` as `i64` (unsigned values beyond
/// `i64::MAX` become `i64::MAX`, which no id check accepts). Float types append nothing.
pub(super) fn decode_i64(ty: ValueType, block: &[u8], out: &mut Vec<i64>) {
    macro_rules! go {
        ($t:ty, $n:expr) => {
            out.extend(
                block.chunks_exact($n).map(|c| {
                    i64::try_from(<$t>::from_be_bytes(array::<$n>(c))).unwrap_or(i64::MAX)
                }),
            )
        };
    }
    match ty {
        ValueType::Char => go!(i8, 1),
        ValueType::UnsignedChar => go!(u8, 1),
        ValueType::Short => go!(i16, 2),
        ValueType::UnsignedShort => go!(u16, 2),
        ValueType::Int | ValueType::IdType => go!(i32, 4),
        ValueType::UnsignedInt => go!(u32, 4),
        ValueType::Long | ValueType::Int64 => go!(i64, 8),
        ValueType::UnsignedLong | ValueType::UnsignedInt64 => go!(u64, 8),
        ValueType::Float | ValueType::Double => {}
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
            .contains("not supported"));
        assert!(ValueType::parse(b"quaternion")
            .unwrap_err()
            .contains("unknown"));
    }

    #[test]
    fn big_endian_decoding() {
        let mut f = Vec::new();
        decode_f64(ValueType::Float, &1.5f32.to_be_bytes(), &mut f);
        decode_f64(ValueType::Short, &(-3i16).to_be_bytes(), &mut f);
        decode_f64(ValueType::UnsignedChar, &[200], &mut f);
        assert_eq!(f, vec![1.5, -3.0, 200.0]);
        let mut i = Vec::new();
        decode_i64(ValueType::Int, &(-7i32).to_be_bytes(), &mut i);
        decode_i64(ValueType::UnsignedInt64, &u64::MAX.to_be_bytes(), &mut i);
        assert_eq!(i, vec![-7, i64::MAX]);
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
