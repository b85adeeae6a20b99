//! FBX units and axes to glTF's (metres, +Y up, +Z front, right-handed).

use glam::{DMat3, DMat4, DVec3};

/// One of the six signed axes of an FBX file's `GlobalSettings` (ufbx's coordinate axes).
fn axis_vector(axis: ufbx::CoordinateAxis) -> Option<DVec3> {
    use ufbx::CoordinateAxis as A;
    Some(match axis {
        A::PositiveX => DVec3::X,
        A::NegativeX => DVec3::NEG_X,
        A::PositiveY => DVec3::Y,
        A::NegativeY => DVec3::NEG_Y,
        A::PositiveZ => DVec3::Z,
        A::NegativeZ => DVec3::NEG_Z,
        A::Unknown => return None,
    })
}

fn axis_name(axis: ufbx::CoordinateAxis) -> &'static str {
    use ufbx::CoordinateAxis as A;
    match axis {
        A::PositiveX => "+X",
        A::NegativeX => "-X",
        A::PositiveY => "+Y",
        A::NegativeY => "-Y",
        A::PositiveZ => "+Z",
        A::NegativeZ => "-Z",
        A::Unknown => "unknown",
    }
}

/// The change of space from a file's to glTF's.
///
/// `matrix = s · A`, where s is the file's unit in metres and the rows of A are the file's
/// right, up and front directions (so they land on +X, +Y and +Z). A point p of the file
/// becomes `matrix · p`; a joint's world transform W becomes `matrix · W · matrix⁻¹`
/// (rotation `A R Aᵀ`, translation `s A t`: same scale as in the file), so skinning
/// matrices conjugate the same way and LBS commutes with the change. When A is a
/// reflection (a left-handed file), triangles must be flipped (`mirrored`).
#[derive(Debug, Clone, PartialEq)]
pub struct SpaceConversion {
    pub matrix: DMat4,
    pub mirrored: bool,
    /// What was converted, for `inspect`.
    pub description: String,
}

impl SpaceConversion {
    /// The conversion of a scene with `axes` and `unit_meters`; falls back to identity axes
    /// or unit 1 (with a warning in `warnings`) when the file's are unusable.
    pub fn new(axes: &ufbx::CoordinateAxes, unit_meters: f64, warnings: &mut Vec<String>) -> Self {
        let rows = [axes.right, axes.up, axes.front].map(axis_vector);
        let basis = match rows {
            [Some(r), Some(u), Some(f)] if DMat3::from_cols(r, u, f).determinant() != 0.0 => {
                DMat3::from_cols(r, u, f).transpose()
            }
            _ => {
                warnings.push(format!(
                    "the file's axes (right {}, up {}, front {}) are not usable: kept as they are",
                    axis_name(axes.right),
                    axis_name(axes.up),
                    axis_name(axes.front)
                ));
                DMat3::IDENTITY
            }
        };
        let scale = if unit_meters.is_finite() && unit_meters > 0.0 {
            unit_meters
        } else {
            warnings.push(format!(
                "the file's unit ({unit_meters} m) is not usable: taken as 1 m"
            ));
            1.0
        };
        let mirrored = basis.determinant() < 0.0;
        let description = format!(
            "file: {} up, {} front, {} right, unit {} m{}; converted to glTF's metres, +Y up, \
             +Z front, right-handed",
            axis_name(axes.up),
            axis_name(axes.front),
            axis_name(axes.right),
            scale,
            if mirrored {
                " (left-handed: mirrored, triangles flipped)"
            } else {
                ""
            }
        );
        Self {
            matrix: DMat4::from_mat3(basis * scale),
            mirrored,
            description,
        }
    }

    /// A point of the file in glTF's space.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.matrix.transform_point3(p)
    }

    /// A joint's world transform in glTF's space: `matrix · W · matrix⁻¹`.
    pub fn frame(&self, world: DMat4) -> DMat4 {
        self.matrix * world * self.matrix.inverse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ufbx::CoordinateAxis as A;

    #[test]
    fn z_up_centimetres_become_y_up_metres() {
        // 3ds Max: +Z up, -Y front, +X right, centimetres.
        let axes = ufbx::CoordinateAxes {
            right: A::PositiveX,
            up: A::PositiveZ,
            front: A::NegativeY,
        };
        let conversion = SpaceConversion::new(&axes, 0.01, &mut Vec::new());
        assert!(!conversion.mirrored);
        let p = conversion.point(DVec3::new(100.0, -200.0, 300.0));
        assert!(p.distance(DVec3::new(1.0, 3.0, 2.0)) < 1e-12, "{p}");
        // A joint frame keeps unit scale and maps its translation like a point.
        let world = DMat4::from_translation(DVec3::new(100.0, -200.0, 300.0));
        let frame = conversion.frame(world);
        assert!(
            frame.abs_diff_eq(DMat4::from_translation(p), 1e-12),
            "{frame}"
        );
    }

    #[test]
    fn left_handed_files_are_mirrored_and_bad_settings_warn() {
        let axes = ufbx::CoordinateAxes {
            right: A::NegativeX,
            up: A::PositiveY,
            front: A::PositiveZ,
        };
        let mut warnings = Vec::new();
        assert!(SpaceConversion::new(&axes, 1.0, &mut warnings).mirrored);
        assert!(warnings.is_empty());
        let broken = ufbx::CoordinateAxes {
            right: A::PositiveY,
            up: A::PositiveY,
            front: A::Unknown,
        };
        let conversion = SpaceConversion::new(&broken, f64::NAN, &mut warnings);
        assert_eq!(conversion.matrix, DMat4::IDENTITY);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
    }
}
