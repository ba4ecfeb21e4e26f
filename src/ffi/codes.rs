//! The C enums of the ABI and their codes as C passes them in.
//!
//! C may pass any `int` where an enum is declared, so no function takes a Rust enum from C:
//! each enum `CylvolX` has a transparent code type (named `CylvolX` in the header too) that
//! [`Code::decode`] checks, turning an unknown value into
//! [`CylvolStatus::InvalidArgument`](super::CylvolStatus::InvalidArgument).

use super::status::Failure;

/// The type of the values of a caller array.
/// cbindgen:rename-all=prefix:CYLVOL_VALUE_
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolValueType {
    /// `float`.
    F32 = 0,
    /// `double`.
    F64 = 1,
}

/// The type of the indices (offsets and connectivity) of a caller cell array.
/// cbindgen:rename-all=prefix:CYLVOL_INDEX_
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolIndexType {
    /// `int32_t` (`vtkCellArray` with 32-bit storage).
    I32 = 0,
    /// `int64_t` (`vtkCellArray` with 64-bit storage, VTK's default).
    I64 = 1,
}

/// Whether a scalar array holds one tuple per point or one per cell.
/// cbindgen:rename-all=prefix:CYLVOL_
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolAssociation {
    /// One tuple per point (interpolated inside cells).
    POINT_DATA = 0,
    /// One tuple per cell (constant inside each cell).
    CELL_DATA = 1,
}

/// The acceleration structure a volume is built with.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolStructure {
    /// Chosen from the mesh: the BVH of the family whose bounds have the smaller surface area
    /// over a sample of cells (cylindrical for turbomachinery meshes).
    Auto = 0,
    /// Two-level grid in `(x, y, z)`.
    CartesianGrid = 1,
    /// Two-level grid in `(r, θ, h)` about the axis.
    CylindricalGrid = 2,
    /// Binned-SAH BVH of boxes.
    CartesianBvh = 3,
    /// Binned-SAH BVH of cylindrical sectors.
    CylindricalBvh = 4,
}

/// The sampling path of the ray caster.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolPath {
    /// Previous cell, face neighbours, then the structure; transparent cells skipped.
    Fast = 0,
    /// Every sample located from scratch through the structure (as the LDAV 2015 talk measured).
    Paper = 1,
}

/// How the scalar is interpolated inside a cell.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolInterpolation {
    /// Trilinear (point data) — the default.
    Linear = 0,
    /// The value of the corner nearest in parametric coordinates (VTK's nearest
    /// interpolation); gradients stay those of the trilinear interpolant.
    Nearest = 1,
}

/// How a ray's samples make its pixel; the values are those of VTK's `vtkVolumeMapper`
/// blend modes (`COMPOSITE_BLEND`, `MAXIMUM_INTENSITY_BLEND`, `MINIMUM_INTENSITY_BLEND`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolBlend {
    /// Front-to-back emission-absorption compositing — the default.
    Composite = 0,
    /// Maximum-intensity projection: the colour and the opacity per unit distance of the
    /// largest scalar sampled on the ray (no shading, gradient opacity or early termination).
    Maximum = 1,
    /// Minimum-intensity projection: the same for the smallest scalar.
    Minimum = 2,
}

/// The pixel format of a render's output.
/// cbindgen:rename-all=prefix:CYLVOL_PIXELS_
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolPixelFormat {
    /// 4 bytes a pixel, premultiplied RGBA, each channel `round(255 · clamp(v, 0, 1))`.
    RGBA8 = 0,
    /// 4 floats a pixel, premultiplied RGBA in `[0, 1]`.
    RGBA_F32 = 1,
}

/// How a [`super::CylvolCamera`] is given.
/// cbindgen:rename-all=prefix:CYLVOL_CAMERA_
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylvolCameraMode {
    /// Eye, focal point, view-up and view angle or parallel scale (`vtkCamera`'s terms).
    LOOK_AT = 0,
    /// View and projection matrices (data space to clip space).
    MATRICES = 1,
}

/// An enum value as C passes it: checked by [`Code::decode`].
pub trait Code: Copy {
    /// The enum.
    type Enum: Copy + Into<i32> + 'static;
    /// The enum's C name, for messages.
    const NAME: &'static str;
    /// Every value of the enum.
    const ALL: &'static [Self::Enum];
    /// The raw value.
    fn raw(self) -> i32;
    /// The enum value, or [`CylvolStatus::InvalidArgument`](super::CylvolStatus::InvalidArgument)
    /// naming the argument `what`.
    fn decode(self, what: &str) -> Result<Self::Enum, Failure> {
        Self::ALL
            .iter()
            .copied()
            .find(|e| (*e).into() == self.raw())
            .ok_or_else(|| {
                Failure::invalid(format!(
                    "{what} = {} is not a {} value",
                    self.raw(),
                    Self::NAME
                ))
            })
    }
}

macro_rules! code {
    ($(#[$doc:meta])* $code:ident, $enum:ident, [$($v:ident),+]) => {
        $(#[$doc])*
        #[repr(transparent)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub struct $code(pub i32);

        impl From<$enum> for $code {
            fn from(e: $enum) -> $code {
                $code(e as i32)
            }
        }

        impl From<$enum> for i32 {
            fn from(e: $enum) -> i32 {
                e as i32
            }
        }

        impl Code for $code {
            type Enum = $enum;
            const NAME: &'static str = stringify!($enum);
            const ALL: &'static [$enum] = &[$($enum::$v),+];
            fn raw(self) -> i32 {
                self.0
            }
        }
    };
}

code!(
    /// A [`CylvolValueType`] as C passes it (named `CylvolValueType` in the header).
    ValueTypeCode, CylvolValueType, [F32, F64]
);
code!(
    /// A [`CylvolIndexType`] as C passes it (named `CylvolIndexType` in the header).
    IndexTypeCode, CylvolIndexType, [I32, I64]
);
code!(
    /// A [`CylvolAssociation`] as C passes it (named `CylvolAssociation` in the header).
    AssociationCode, CylvolAssociation, [POINT_DATA, CELL_DATA]
);
code!(
    /// A [`CylvolStructure`] as C passes it (named `CylvolStructure` in the header).
    StructureCode, CylvolStructure,
    [Auto, CartesianGrid, CylindricalGrid, CartesianBvh, CylindricalBvh]
);
code!(
    /// A [`CylvolPath`] as C passes it (named `CylvolPath` in the header).
    PathCode, CylvolPath, [Fast, Paper]
);
code!(
    /// A [`CylvolInterpolation`] as C passes it (named `CylvolInterpolation` in the header).
    InterpolationCode, CylvolInterpolation, [Linear, Nearest]
);
code!(
    /// A [`CylvolBlend`] as C passes it (named `CylvolBlend` in the header).
    BlendCode, CylvolBlend, [Composite, Maximum, Minimum]
);
code!(
    /// A [`CylvolPixelFormat`] as C passes it (named `CylvolPixelFormat` in the header).
    PixelFormatCode, CylvolPixelFormat, [RGBA8, RGBA_F32]
);
code!(
    /// A [`CylvolCameraMode`] as C passes it (named `CylvolCameraMode` in the header).
    CameraModeCode, CylvolCameraMode, [LOOK_AT, MATRICES]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::CylvolStatus;

    #[test]
    fn codes_decode_their_values_and_refuse_others() {
        assert_eq!(
            ValueTypeCode(1).decode("points_type").unwrap(),
            CylvolValueType::F64
        );
        assert_eq!(
            StructureCode::from(CylvolStructure::CylindricalBvh)
                .decode("structure")
                .unwrap(),
            CylvolStructure::CylindricalBvh
        );
        let f = PixelFormatCode(2).decode("format").unwrap_err();
        assert_eq!(f.status, CylvolStatus::InvalidArgument);
        assert_eq!(f.detail, "format = 2 is not a CylvolPixelFormat value");
        assert!(CameraModeCode(-1).decode("mode").is_err());
    }
}
