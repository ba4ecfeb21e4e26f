//! Binary elements of VTK data arrays: the ten numeric types VTK stores, read in either byte
//! order and converted to `f64` values, `f64` tuples or `i64` integers. Shared by the XML
//! readers (whose files say their byte order) and the legacy reader (always big-endian), so
//! every reader converts the same way: in parallel, and without an intermediate copy where
//! the values are read one at a time ([`Integers`]).

use rayon::prelude::*;

/// The numeric element types of a VTK XML `DataArray`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ScalarType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl ScalarType {
    /// The type named by a `type` attribute (`None` for strings, bits and unknown names).
    pub fn parse(name: &str) -> Option<ScalarType> {
        Some(match name {
            "Int8" | "Char" => ScalarType::I8,
            "UInt8" | "UnsignedChar" => ScalarType::U8,
            "Int16" => ScalarType::I16,
            "UInt16" => ScalarType::U16,
            "Int32" => ScalarType::I32,
            "UInt32" => ScalarType::U32,
            "Int64" | "vtkIdType" => ScalarType::I64,
            "UInt64" => ScalarType::U64,
            "Float32" => ScalarType::F32,
            "Float64" => ScalarType::F64,
            _ => return None,
        })
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            ScalarType::I8 | ScalarType::U8 => 1,
            ScalarType::I16 | ScalarType::U16 => 2,
            ScalarType::I32 | ScalarType::U32 | ScalarType::F32 => 4,
            ScalarType::I64 | ScalarType::U64 | ScalarType::F64 => 8,
        }
    }

    pub(super) fn is_float(self) -> bool {
        matches!(self, ScalarType::F32 | ScalarType::F64)
    }
}

/// A stored element type, read from its bytes in either byte order.
trait Element: Sized {
    const SIZE: usize;
    /// The element at the start of `bytes` (which holds at least `SIZE` bytes).
    fn read(bytes: &[u8], big_endian: bool) -> Self;
    fn to_f64(self) -> f64;
    /// As `i64`, unsigned values beyond `i64::MAX` saturating (floats: 0, never asked).
    fn to_i64(self) -> i64;
}

macro_rules! element {
    ($($t:ty => $to_i64:expr),* $(,)?) => {$(
        impl Element for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            #[inline]
            fn read(bytes: &[u8], big_endian: bool) -> Self {
                let mut a = [0; std::mem::size_of::<$t>()];
                a.copy_from_slice(&bytes[..Self::SIZE]);
                if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn to_i64(self) -> i64 {
                let convert: fn($t) -> i64 = $to_i64;
                convert(self)
            }
        }
    )*};
}

element!(
    i8 => i64::from, u8 => i64::from, i16 => i64::from, u16 => i64::from,
    i32 => i64::from, u32 => i64::from, i64 => |v| v,
    u64 => |v| i64::try_from(v).unwrap_or(i64::MAX),
    f32 => |_| 0, f64 => |_| 0,
);

/// Evaluates `$body` with `$T` the Rust type of `$ty`'s elements.
macro_rules! with_element_type {
    ($ty:expr, $T:ident => $body:expr) => {
        match $ty {
            ScalarType::I8 => {
                type $T = i8;
                $body
            }
            ScalarType::U8 => {
                type $T = u8;
                $body
            }
            ScalarType::I16 => {
                type $T = i16;
                $body
            }
            ScalarType::U16 => {
                type $T = u16;
                $body
            }
            ScalarType::I32 => {
                type $T = i32;
                $body
            }
            ScalarType::U32 => {
                type $T = u32;
                $body
            }
            ScalarType::I64 => {
                type $T = i64;
                $body
            }
            ScalarType::U64 => {
                type $T = u64;
                $body
            }
            ScalarType::F32 => {
                type $T = f32;
                $body
            }
            ScalarType::F64 => {
                type $T = f64;
                $body
            }
        }
    };
}

/// Converts decoded bytes holding elements of `ty` into values `N` elements at a time, in
/// parallel: `make` receives each tuple as `f64`s (a trailing part tuple is dropped).
pub(super) fn to_tuples<const N: usize, T: Send>(
    bytes: &[u8],
    ty: ScalarType,
    big_endian: bool,
    make: impl Fn([f64; N]) -> T + Sync,
) -> Vec<T> {
    with_element_type!(ty, E => {
        bytes
            .par_chunks_exact(E::SIZE * N)
            .map(|tuple| {
                make(std::array::from_fn(|j| {
                    E::read(&tuple[j * E::SIZE..], big_endian).to_f64()
                }))
            })
            .collect()
    })
}

/// Reads `count` elements of `ty` from decoded bytes as `f64`.
pub(super) fn to_f64(bytes: &[u8], ty: ScalarType, big_endian: bool) -> Vec<f64> {
    to_tuples(bytes, ty, big_endian, |[v]: [f64; 1]| v)
}

/// Decoded bytes of an integer array, read an element at a time as `i64` (unsigned values
/// beyond `i64::MAX` saturate), so large arrays need no `i64` copy.
#[derive(Clone, Copy, Debug)]
pub(super) struct Integers<'a> {
    bytes: &'a [u8],
    ty: ScalarType,
    big_endian: bool,
}

impl<'a> Integers<'a> {
    /// No elements.
    pub(super) const EMPTY: Integers<'static> = Integers {
        bytes: &[],
        ty: ScalarType::I64,
        big_endian: false,
    };

    /// `None` for a float type.
    pub(super) fn new(bytes: &'a [u8], ty: ScalarType, big_endian: bool) -> Option<Self> {
        is_integer(ty).then_some(Integers {
            bytes,
            ty,
            big_endian,
        })
    }

    /// How many whole elements the bytes hold.
    pub(super) fn len(&self) -> usize {
        self.bytes.len() / self.ty.size()
    }

    /// Element `k` (`k < len()`; beyond it, 0).
    #[inline]
    pub(super) fn get(&self, k: usize) -> i64 {
        with_element_type!(self.ty, E => {
            match self.bytes.get(k * E::SIZE..(k + 1) * E::SIZE) {
                Some(b) => E::read(b, self.big_endian).to_i64(),
                None => 0,
            }
        })
    }

    /// Every element, converted in parallel.
    pub(super) fn to_vec(self) -> Vec<i64> {
        (0..self.len())
            .into_par_iter()
            .map(|k| self.get(k))
            .collect()
    }
}

/// Reads integer elements of `ty` from decoded bytes as `i64` (unsigned values beyond
/// `i64::MAX` saturate; float types give nothing, an error left to the caller).
pub(super) fn to_i64(bytes: &[u8], ty: ScalarType, big_endian: bool) -> Vec<i64> {
    Integers::new(bytes, ty, big_endian).map_or_else(Vec::new, Integers::to_vec)
}

/// Whether integer conversion is possible for this element type.
pub(super) fn is_integer(ty: ScalarType) -> bool {
    !ty.is_float()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_types_convert_in_both_byte_orders() {
        let v: i16 = -300;
        assert_eq!(
            to_f64(&v.to_be_bytes(), ScalarType::I16, true),
            vec![-300.0]
        );
        assert_eq!(to_i64(&v.to_le_bytes(), ScalarType::I16, false), vec![-300]);
        assert_eq!(
            to_i64(&u64::MAX.to_le_bytes(), ScalarType::U64, false),
            vec![i64::MAX]
        );
        assert_eq!(
            to_f64(&1.5f32.to_be_bytes(), ScalarType::F32, true),
            vec![1.5]
        );
    }

    /// Every element type, both byte orders: tuples of three, single values and integers read
    /// one at a time give the values written (integers beyond `i64` saturating), over more
    /// elements than one parallel task takes; a trailing part tuple is dropped.
    #[test]
    fn every_type_converts_alike_by_value_tuple_and_element() {
        let values: Vec<i64> = (0..30_003).map(|i| (i % 251) - 100).collect();
        macro_rules! check {
            ($t:ty, $ty:expr) => {
                for big_endian in [false, true] {
                    let stored: Vec<$t> = values.iter().map(|&v| v as $t).collect();
                    let bytes: Vec<u8> = stored
                        .iter()
                        .flat_map(|v| {
                            if big_endian {
                                v.to_be_bytes().to_vec()
                            } else {
                                v.to_le_bytes().to_vec()
                            }
                        })
                        .collect();
                    let want: Vec<f64> = stored.iter().map(|&v| v as f64).collect();
                    assert_eq!(to_f64(&bytes, $ty, big_endian), want, "{:?}", $ty);
                    let triples = to_tuples(&bytes, $ty, big_endian, |t: [f64; 3]| t);
                    assert_eq!(triples.len(), want.len() / 3);
                    assert!(triples.iter().flatten().eq(&want[..want.len() / 3 * 3]));
                    let ints = Integers::new(&bytes, $ty, big_endian);
                    if is_integer($ty) {
                        let ints = ints.unwrap();
                        assert_eq!(ints.len(), values.len());
                        let want: Vec<i64> = want.iter().map(|&v| v as i64).collect();
                        assert_eq!(to_i64(&bytes, $ty, big_endian), want, "{:?}", $ty);
                        assert_eq!(ints.get(values.len()), 0, "beyond the end");
                    } else {
                        assert!(ints.is_none());
                        assert!(to_i64(&bytes, $ty, big_endian).is_empty());
                    }
                }
            };
        }
        check!(i8, ScalarType::I8);
        check!(u8, ScalarType::U8);
        check!(i16, ScalarType::I16);
        check!(u16, ScalarType::U16);
        check!(i32, ScalarType::I32);
        check!(u32, ScalarType::U32);
        check!(i64, ScalarType::I64);
        check!(u64, ScalarType::U64);
        check!(f32, ScalarType::F32);
        check!(f64, ScalarType::F64);
        let top = u64::MAX - 5;
        let bytes = top.to_be_bytes();
        let ints = Integers::new(&bytes, ScalarType::U64, true).unwrap();
        assert_eq!(ints.get(0), i64::MAX);
    }
}
