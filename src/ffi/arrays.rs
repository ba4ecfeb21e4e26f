//! Reading caller arrays: checked pointers, lengths and alignment, and the conversion of
//! `float`/`double` values and `int32_t`/`int64_t` indices to the library's types.

use std::borrow::Cow;
use std::ffi::c_void;

use glam::DVec3;

use super::codes::{CylvolIndexType, CylvolValueType};
use super::status::{CylvolStatus, Failure};

/// `a × b` for array sizes, or an error naming `what` when it overflows.
pub fn product(a: usize, b: usize, what: &str) -> Result<usize, Failure> {
    a.checked_mul(b).ok_or_else(|| {
        Failure::invalid(format!(
            "{what}: {a} × {b} elements overflow the address space"
        ))
    })
}

/// The caller's `len` elements of `T` at `ptr` as a slice; NULL, a misaligned pointer or a
/// size beyond `isize::MAX` bytes is an error naming `what`. `len = 0` accepts any non-NULL
/// pointer.
///
/// # Safety
/// A non-NULL `ptr` must point to `len` readable, initialised elements that stay unchanged
/// during the call.
pub unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], Failure> {
    if ptr.is_null() {
        return Err(Failure::null(what));
    }
    check_layout::<T>(ptr as usize, len, what)?;
    // SAFETY: non-NULL, aligned, size in range, and the caller vouches for the contents.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// [`fn@slice`] for writing.
///
/// # Safety
/// A non-NULL `ptr` must point to `len` writable elements that nothing else uses during the
/// call.
pub unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    len: usize,
    what: &str,
) -> Result<&'a mut [T], Failure> {
    if ptr.is_null() {
        return Err(Failure::null(what));
    }
    check_layout::<T>(ptr as usize, len, what)?;
    // SAFETY: as for `slice`, and the caller gives exclusive access.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

fn check_layout<T>(address: usize, len: usize, what: &str) -> Result<(), Failure> {
    if address % std::mem::align_of::<T>() != 0 {
        return Err(Failure::invalid(format!(
            "{what} is not aligned for its element type ({} bytes)",
            std::mem::align_of::<T>()
        )));
    }
    let bytes = product(len, std::mem::size_of::<T>().max(1), what)?;
    if bytes > isize::MAX as usize || address.checked_add(bytes).is_none() {
        return Err(Failure::invalid(format!(
            "{what}: {len} elements are too many"
        )));
    }
    Ok(())
}

/// `len` values of `value_type` at `ptr` as `f64`, as they are (NaN and infinities included:
/// the caller checks the ones it uses).
///
/// # Safety
/// As [`fn@slice`].
pub unsafe fn values(
    ptr: *const c_void,
    value_type: CylvolValueType,
    len: usize,
    what: &str,
) -> Result<Vec<f64>, Failure> {
    let out: Vec<f64> = match value_type {
        CylvolValueType::F32 => unsafe { slice(ptr as *const f32, len, what)? }
            .iter()
            .map(|&v| v as f64)
            .collect(),
        CylvolValueType::F64 => unsafe { slice(ptr as *const f64, len, what)? }.to_vec(),
    };
    Ok(out)
}

/// An error naming the first non-finite value of `values`, if any.
pub fn finite(values: &[f64], what: &str) -> Result<(), Failure> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(not_finite(what, i, values[i])),
        None => Ok(()),
    }
}

/// The error for `what[i] = value`, which is not finite.
fn not_finite(what: &str, i: usize, value: f64) -> Failure {
    Failure::invalid(format!("{what}[{i}] = {value} is not finite"))
}

/// `len` indices of `index_type` at `ptr` as `i64`: borrowed where they are `i64` already
/// (VTK's 64-bit cell arrays), else converted.
///
/// # Safety
/// As [`fn@slice`].
pub unsafe fn indices<'a>(
    ptr: *const c_void,
    index_type: CylvolIndexType,
    len: usize,
    what: &str,
) -> Result<Cow<'a, [i64]>, Failure> {
    Ok(match index_type {
        CylvolIndexType::I32 => Cow::Owned(
            unsafe { slice(ptr as *const i32, len, what)? }
                .iter()
                .map(|&v| v as i64)
                .collect(),
        ),
        CylvolIndexType::I64 => Cow::Borrowed(unsafe { slice(ptr as *const i64, len, what)? }),
    })
}

/// `n` points of three values of `value_type` at `ptr`, each finite (else an error naming
/// the first value that is not), converted in one pass.
///
/// # Safety
/// As [`fn@slice`] for `3 n` values.
pub unsafe fn points(
    ptr: *const c_void,
    value_type: CylvolValueType,
    n: usize,
    what: &str,
) -> Result<Vec<DVec3>, Failure> {
    let len = product(n, 3, what)?;
    fn convert<T: Copy + Into<f64>>(xyz: &[T], what: &str) -> Result<Vec<DVec3>, Failure> {
        let points: Vec<DVec3> = xyz
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0].into(), c[1].into(), c[2].into()))
            .collect();
        match points.iter().position(|p| !p.is_finite()) {
            Some(i) => {
                let k = (0..3).find(|&k| !points[i][k].is_finite()).unwrap_or(0);
                Err(not_finite(what, 3 * i + k, points[i][k]))
            }
            None => Ok(points),
        }
    }
    match value_type {
        CylvolValueType::F32 => convert(unsafe { slice(ptr as *const f32, len, what)? }, what),
        CylvolValueType::F64 => convert(unsafe { slice(ptr as *const f64, len, what)? }, what),
    }
}

/// A reference to the object behind a handle, or [`CylvolStatus::NullPointer`].
///
/// # Safety
/// A non-NULL `ptr` must be a live handle of this type not used by another thread.
pub unsafe fn handle<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller vouches for a non-NULL handle.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::null(what))
}

/// A mutable reference to the object behind a handle, or [`CylvolStatus::NullPointer`].
///
/// # Safety
/// As [`handle`], with exclusive access.
pub unsafe fn handle_mut<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller vouches for a non-NULL handle used by this thread only.
    unsafe { ptr.as_mut() }.ok_or_else(|| Failure::null(what))
}

/// Frees a handle made by `Box::into_raw` (NULL is fine), inside the panic boundary of
/// `function`.
///
/// # Safety
/// `ptr` NULL or a live handle of this type, not used afterwards.
pub unsafe fn free_handle<T>(function: &str, ptr: *mut T) {
    let _ = super::status::guard(function, || {
        if !ptr.is_null() {
            // SAFETY: the caller vouches for a handle made by `Box::into_raw`.
            drop(unsafe { Box::from_raw(ptr) });
        }
        Ok(())
    });
}

/// Writes `value` through an output pointer, or fails with [`CylvolStatus::NullPointer`].
///
/// # Safety
/// A non-NULL `ptr` must be valid for writing a `T`.
pub unsafe fn write<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if ptr.is_null() {
        return Err(Failure::new(
            CylvolStatus::NullPointer,
            format!("{what} is NULL"),
        ));
    }
    if ptr as usize % std::mem::align_of::<T>() != 0 {
        return Err(Failure::invalid(format!("{what} is not aligned")));
    }
    // SAFETY: non-NULL and aligned; the caller vouches for validity.
    unsafe { ptr.write(value) };
    Ok(())
}
