//! Status codes, their messages, the detail of the last failure on each thread, and the panic
//! boundary every exported function runs inside ([`guard`]).
//!
//! A failing call returns a [`CylvolStatus`] and leaves a sentence saying what was wrong in a
//! thread-local buffer ([`cylvol_last_error`]); calls on a volume also keep it in the volume
//! ([`super::cylvol_volume_last_error`]). A panic inside the library (a bug) never crosses the
//! C boundary: [`guard`] catches it and the call returns [`CylvolStatus::Panic`].

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::error::MeshError;

/// The result of every fallible call.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolStatus {
    /// Success.
    Ok = 0,
    /// A required pointer was NULL.
    NullPointer = 1,
    /// NaN or infinite input, a zero size, a bad enum value or a bad parameter.
    InvalidArgument = 2,
    /// An index (point id, component, offset) out of range.
    OutOfRange = 3,
    /// An array's length disagrees with the others.
    LengthMismatch = 4,
    /// A VTK cell type other than hexahedron, voxel, wedge, pyramid or tetrahedron.
    UnsupportedCell = 5,
    /// An empty mesh, inverted cells, …
    InvalidMesh = 6,
    /// A render was asked for with no scalar array set.
    NoScalars = 7,
    /// An internal panic was caught (a bug in cylvol; the process goes on).
    Panic = 8,
}

impl CylvolStatus {
    /// Every status, in code order.
    pub fn all() -> [CylvolStatus; 9] {
        [
            CylvolStatus::Ok,
            CylvolStatus::NullPointer,
            CylvolStatus::InvalidArgument,
            CylvolStatus::OutOfRange,
            CylvolStatus::LengthMismatch,
            CylvolStatus::UnsupportedCell,
            CylvolStatus::InvalidMesh,
            CylvolStatus::NoScalars,
            CylvolStatus::Panic,
        ]
    }

    /// The static, NUL-terminated message of this status.
    pub fn message(self) -> &'static CStr {
        match self {
            CylvolStatus::Ok => c"ok",
            CylvolStatus::NullPointer => c"a required pointer was NULL",
            CylvolStatus::InvalidArgument => {
                c"invalid argument (NaN or infinite value, zero size, bad enum value or parameter)"
            }
            CylvolStatus::OutOfRange => c"an index (point id, component, offset) is out of range",
            CylvolStatus::LengthMismatch => c"an array's length disagrees with the others",
            CylvolStatus::UnsupportedCell => {
                c"unsupported VTK cell type (only hexahedron, voxel, wedge, pyramid, tetrahedron)"
            }
            CylvolStatus::InvalidMesh => c"invalid mesh (empty, inverted cells, ...)",
            CylvolStatus::NoScalars => c"no scalar array is set",
            CylvolStatus::Panic => c"internal error: a panic was caught (a bug in cylvol)",
        }
    }
}

/// A status code as C passes it in: any `int` value (unknown ones are reported, not trusted).
/// Named `CylvolStatus` in the header.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StatusCode(pub i32);

impl From<CylvolStatus> for StatusCode {
    fn from(s: CylvolStatus) -> StatusCode {
        StatusCode(s as i32)
    }
}

/// A failed call: its status and a sentence saying what was wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// The status returned.
    pub status: CylvolStatus,
    /// The detail kept for [`cylvol_last_error`].
    pub detail: String,
}

impl Failure {
    /// A failure with a status and a detail.
    pub fn new(status: CylvolStatus, detail: impl Into<String>) -> Failure {
        Failure {
            status,
            detail: detail.into(),
        }
    }

    /// [`CylvolStatus::NullPointer`] for the argument `name`.
    pub fn null(name: &str) -> Failure {
        Failure::new(CylvolStatus::NullPointer, format!("{name} is NULL"))
    }

    /// [`CylvolStatus::InvalidArgument`].
    pub fn invalid(detail: impl Into<String>) -> Failure {
        Failure::new(CylvolStatus::InvalidArgument, detail)
    }
}

/// The status a mesh error is reported with.
pub fn mesh_status(e: &MeshError) -> CylvolStatus {
    match e {
        MeshError::Empty { .. } | MeshError::InvertedCells { .. } => CylvolStatus::InvalidMesh,
        MeshError::NonFinitePoint { .. } => CylvolStatus::InvalidArgument,
        MeshError::IndexOutOfRange { .. } | MeshError::CellArrays(_) => CylvolStatus::OutOfRange,
        MeshError::UnsupportedCellTypes { .. } => CylvolStatus::UnsupportedCell,
        MeshError::WrongVertexCount { .. } | MeshError::ArrayLength { .. } => {
            CylvolStatus::LengthMismatch
        }
    }
}

impl From<MeshError> for Failure {
    fn from(e: MeshError) -> Failure {
        Failure::new(mesh_status(&e), e.to_string())
    }
}

impl From<crate::Error> for Failure {
    fn from(e: crate::Error) -> Failure {
        match e {
            crate::Error::Mesh(m) => m.into(),
            other => Failure::invalid(other.to_string()),
        }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// A C string of `text`, interior NUL bytes replaced.
pub fn c_string(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{FFFD}")).unwrap_or_default()
}

fn set_last_error(text: &str) {
    LAST_ERROR.with(|e| *e.borrow_mut() = c_string(text));
}

/// The detail of the last failure on this thread (`""` if none), as Rust text.
pub fn last_error_text() -> String {
    LAST_ERROR.with(|e| e.borrow().to_string_lossy().into_owned())
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("a panic without a message")
}

/// The panic boundary: runs `body`, turns a panic into a [`CylvolStatus::Panic`] failure, and
/// records any failure's detail (prefixed with `function`) as this thread's last error. Every
/// exported function runs its whole body inside it.
pub fn guard<T>(function: &str, body: impl FnOnce() -> Result<T, Failure>) -> Result<T, Failure> {
    let result = match catch_unwind(AssertUnwindSafe(body)) {
        Ok(r) => r,
        Err(payload) => Err(Failure::new(
            CylvolStatus::Panic,
            format!("internal panic: {}", panic_text(payload.as_ref())),
        )),
    };
    result.map_err(|f| {
        let f = Failure {
            detail: format!("{function}: {}", f.detail),
            ..f
        };
        set_last_error(&f.detail);
        f
    })
}

/// [`guard`] for calls that return only a status.
pub fn status(function: &str, body: impl FnOnce() -> Result<(), Failure>) -> CylvolStatus {
    match guard(function, body) {
        Ok(()) => CylvolStatus::Ok,
        Err(f) => f.status,
    }
}

/// The version of the library, e.g. `"0.1.0"` (a static string).
#[no_mangle]
pub extern "C" fn cylvol_version() -> *const c_char {
    const VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"unknown",
        };
    guard("cylvol_version", || Ok(VERSION.as_ptr())).unwrap_or(c"".as_ptr())
}

/// The static message of a status; `"unknown status"` for a value that is none.
#[no_mangle]
pub extern "C" fn cylvol_status_message(status: StatusCode) -> *const c_char {
    guard("cylvol_status_message", || {
        Ok(CylvolStatus::all()
            .iter()
            .find(|s| **s as i32 == status.0)
            .map_or(c"unknown status".as_ptr(), |s| s.message().as_ptr()))
    })
    .unwrap_or(c"unknown status".as_ptr())
}

/// The detail of the last failed call on this thread (any function), or `""` if none. The
/// string stays valid until the next failing cylvol call on this thread.
#[no_mangle]
pub extern "C" fn cylvol_last_error() -> *const c_char {
    guard("cylvol_last_error", || {
        Ok(LAST_ERROR.with(|e| e.borrow().as_ptr()))
    })
    .unwrap_or(c"".as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_the_boundary_becomes_a_status_and_a_detail() {
        let s = status("cylvol_test", || {
            let v: Vec<u8> = Vec::new();
            let i = v.len() + 3;
            // An out-of-bounds index: a panic the boundary must catch.
            Ok(std::hint::black_box(v)[i]).map(|_: u8| ())
        });
        assert_eq!(s, CylvolStatus::Panic);
        let detail = last_error_text();
        assert!(
            detail.starts_with("cylvol_test: internal panic"),
            "{detail}"
        );
        assert!(detail.contains("index out of bounds"), "{detail}");
    }

    #[test]
    fn failures_are_recorded_and_successes_keep_the_last_detail() {
        let s = status("cylvol_x", || Err(Failure::null("points")));
        assert_eq!(s, CylvolStatus::NullPointer);
        assert_eq!(last_error_text(), "cylvol_x: points is NULL");
        assert_eq!(status("cylvol_y", || Ok(())), CylvolStatus::Ok);
        assert_eq!(last_error_text(), "cylvol_x: points is NULL");
    }

    #[test]
    fn every_status_has_its_own_message_and_unknown_codes_are_named() {
        let mut seen = std::collections::HashSet::new();
        for s in CylvolStatus::all() {
            let m = unsafe { CStr::from_ptr(cylvol_status_message(s.into())) };
            assert!(seen.insert(m.to_owned()), "{s:?}");
        }
        for bad in [-1, 9, i32::MAX] {
            let m = unsafe { CStr::from_ptr(cylvol_status_message(StatusCode(bad))) };
            assert_eq!(m.to_str().unwrap(), "unknown status");
        }
    }
}
