//! Sampling animation clips into local transforms (glTF 2.0 interpolation).

use crate::{Clip, Interpolation, Property, RuntimeError, Track, Trs};
use glam::{Quat, Vec4};

impl Track {
    /// Floats per value: 4 for a rotation quaternion, 3 otherwise.
    pub fn components(&self) -> usize {
        match self.property {
            Property::Rotation => 4,
            Property::Translation | Property::Scale => 3,
        }
    }

    /// Floats stored per key: one value, or in-tangent, value, out-tangent for a cubic spline.
    fn floats_per_key(&self) -> usize {
        match self.interpolation {
            Interpolation::CubicSpline => 3 * self.components(),
            Interpolation::Step | Interpolation::Linear => self.components(),
        }
    }

    /// Element `slot` (0 in-tangent, 1 value, 2 out-tangent for cubic splines; 0 otherwise)
    /// of key `k`, padded to four floats.
    fn element(&self, k: usize, slot: usize) -> Vec4 {
        let c = self.components();
        let start = k * self.floats_per_key() + slot * c;
        let v = &self.values[start..start + c];
        Vec4::new(v[0], v[1], v[2], if c == 4 { v[3] } else { 0.0 })
    }

    /// The key value of key `k`.
    fn key_value(&self, k: usize) -> Vec4 {
        let slot = usize::from(self.interpolation == Interpolation::CubicSpline);
        self.element(k, slot)
    }

    /// The track's value at `time` seconds, padded to four floats, following the glTF 2.0
    /// specification (Appendix C, "Animation sampler interpolation modes"):
    ///
    /// - before the first key or after the last: the first or last key value (clamped);
    /// - STEP: the value of the key at or before `time`;
    /// - LINEAR: `(1 − s) v_k + s v_k+1` with `s = (t − t_k) / (t_k+1 − t_k)`; rotations by
    ///   spherical linear interpolation along the shorter arc;
    /// - CUBICSPLINE: the cubic Hermite spline
    ///   `(2s³ − 3s² + 1) v_k + Δ(s³ − 2s² + s) b_k + (−2s³ + 3s²) v_k+1 + Δ(s³ − s²) a_k+1`
    ///   with `Δ = t_k+1 − t_k`, out-tangent `b_k`, in-tangent `a_k+1`; rotations are then
    ///   normalised.
    pub fn sample(&self, time: f32) -> Vec4 {
        let last = self.times.len() - 1;
        // First key with a time strictly after `time`.
        let next = self.times.partition_point(|&t| t <= time);
        if next == 0 {
            return self.key_value(0);
        }
        if next > last {
            return self.key_value(last);
        }
        let k = next - 1;
        let delta = self.times[next] - self.times[k];
        let s = (time - self.times[k]) / delta;
        let rotation = self.property == Property::Rotation;
        match self.interpolation {
            Interpolation::Step => self.key_value(k),
            Interpolation::Linear if rotation => {
                let a = Quat::from_vec4(self.key_value(k));
                let b = Quat::from_vec4(self.key_value(next));
                Vec4::from(a.slerp(b, s))
            }
            Interpolation::Linear => self.key_value(k).lerp(self.key_value(next), s),
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let value = (2.0 * s3 - 3.0 * s2 + 1.0) * self.element(k, 1)
                    + delta * (s3 - 2.0 * s2 + s) * self.element(k, 2)
                    + (-2.0 * s3 + 3.0 * s2) * self.element(next, 1)
                    + delta * (s3 - s2) * self.element(next, 0);
                if rotation {
                    value.normalize_or_zero()
                } else {
                    value
                }
            }
        }
    }
}

impl Clip {
    /// Checks every track against a rig of `node_count` nodes: node in range, at least one
    /// key, strictly increasing finite times, the value count the interpolation needs,
    /// finite values, non-zero rotation keys. [`Clip::sample`] assumes a validated clip.
    pub fn validate(&self, node_count: usize) -> Result<(), RuntimeError> {
        for (index, track) in self.tracks.iter().enumerate() {
            let bad = |what: String| RuntimeError::BadTrack {
                clip: self.name.clone(),
                track: index,
                node: track.node,
                what,
            };
            if track.node as usize >= node_count {
                return Err(bad(format!("the rig has {node_count} nodes")));
            }
            if track.times.is_empty() {
                return Err(bad("no keys".into()));
            }
            if track.times.iter().any(|t| !t.is_finite())
                || track.times.windows(2).any(|w| w[0] >= w[1])
            {
                return Err(bad(
                    "key times are not finite and strictly increasing".into()
                ));
            }
            let expected = track.times.len() * track.floats_per_key();
            if track.values.len() != expected {
                return Err(bad(format!(
                    "{} values for {} keys, expected {expected}",
                    track.values.len(),
                    track.times.len()
                )));
            }
            if track.values.iter().any(|v| !v.is_finite()) {
                return Err(bad("non-finite value".into()));
            }
            if track.property == Property::Rotation
                && (0..track.times.len()).any(|k| track.key_value(k).length_squared() < 1e-12)
            {
                return Err(bad("zero rotation quaternion".into()));
            }
        }
        Ok(())
    }

    /// Local transforms of every rig node at `time` seconds: the rest transform with the
    /// animated properties replaced by [`Track::sample`] (rotations renormalised).
    ///
    /// - `rig_rest`: #N rest local transforms ([`crate::Rig::rest`]); `out_local`: #N outputs.
    pub fn sample(&self, time: f32, rig_rest: &[Trs], out_local: &mut [Trs]) {
        debug_assert_eq!(rig_rest.len(), out_local.len());
        out_local.copy_from_slice(rig_rest);
        for track in &self.tracks {
            let value = track.sample(time);
            let local = &mut out_local[track.node as usize];
            match track.property {
                Property::Translation => local.translation = value.truncate(),
                Property::Scale => local.scale = value.truncate(),
                Property::Rotation => local.rotation = Quat::from_vec4(value).normalize(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use std::f32::consts::FRAC_PI_2;

    fn track(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
    ) -> Track {
        Track {
            node: 0,
            property,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
        }
    }

    fn clip(tracks: Vec<Track>) -> Clip {
        Clip {
            name: "test".into(),
            duration: 1.0,
            tracks,
        }
    }

    #[test]
    fn invalid_clips_are_rejected() {
        use Interpolation::*;
        use Property::*;
        // Each case breaks one rule of a track and is refused for that rule (`what`).
        let cases = [
            (track(Translation, Linear, &[], &[]), "no keys"),
            (
                track(Translation, Linear, &[0.0, 0.0], &[0.0; 6]),
                "strictly increasing",
            ),
            (
                track(Translation, Linear, &[0.0, 1.0], &[0.0; 5]),
                "5 values for 2 keys",
            ),
            (
                track(Translation, CubicSpline, &[0.0, 1.0], &[0.0; 6]),
                "expected 18",
            ),
            (
                track(Translation, Step, &[0.0], &[f32::NAN, 0.0, 0.0]),
                "non-finite value",
            ),
            (
                track(Rotation, Linear, &[0.0], &[0.0; 4]),
                "zero rotation quaternion",
            ),
            (
                track(Scale, Linear, &[f32::INFINITY], &[1.0; 3]),
                "strictly increasing",
            ),
            (
                Track {
                    node: 3,
                    ..track(Scale, Linear, &[0.0], &[1.0; 3])
                },
                "the rig has 1 nodes",
            ),
        ];
        for (case, reason) in cases {
            match clip(vec![case.clone()]).validate(1) {
                Err(RuntimeError::BadTrack { what, .. }) => {
                    assert!(what.contains(reason), "{case:?}: {what}")
                }
                other => panic!("{case:?}: expected a bad track ({reason}), got {other:?}"),
            }
        }
        let ok = track(Translation, CubicSpline, &[0.0, 1.0], &[0.0; 18]);
        assert!(clip(vec![ok]).validate(1).is_ok());
    }

    #[test]
    fn step_and_linear_clamp_outside_the_keys() {
        let t = track(
            Property::Translation,
            Interpolation::Linear,
            &[1.0, 3.0],
            &[0.0, 0.0, 0.0, 2.0, 4.0, 6.0],
        );
        assert_eq!(t.sample(0.0), Vec4::ZERO);
        assert_eq!(t.sample(2.0), Vec4::new(1.0, 2.0, 3.0, 0.0));
        assert_eq!(t.sample(5.0), Vec4::new(2.0, 4.0, 6.0, 0.0));
        let step = Track {
            interpolation: Interpolation::Step,
            ..t
        };
        assert_eq!(step.sample(2.9), Vec4::ZERO);
        assert_eq!(step.sample(3.0), Vec4::new(2.0, 4.0, 6.0, 0.0));
    }

    #[test]
    fn linear_rotation_takes_the_shorter_arc() {
        let a = Quat::IDENTITY;
        // -q of a 90° turn about z: slerp must still pass through the 45° turn.
        let b = -Quat::from_rotation_z(FRAC_PI_2);
        let values: Vec<f32> = [a, b].iter().flat_map(|q| q.to_array()).collect();
        let t = track(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &values,
        );
        let mid = Quat::from_vec4(t.sample(0.5));
        assert!(mid.angle_between(Quat::from_rotation_z(FRAC_PI_2 / 2.0)) < 1e-3);
    }

    #[test]
    fn cubic_spline_is_hermite_with_scaled_tangents() {
        // One component: p(s) = 3s² − 2s³ between 0 and 1 with zero tangents; tangents of 1
        // over a key gap of 2 add Δ(s³ − 2s² + s) + Δ(s³ − s²).
        let flat = track(
            Property::Translation,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, /* key 1 */ 0.0, 0.0, 0.0, 1.0,
                0.0, 0.0, 0.0, 0.0, 0.0,
            ],
        );
        assert!((flat.sample(1.0).x - 0.5).abs() < 1e-6);
        let mut sloped = flat.clone();
        sloped.values[6] = 1.0; // out-tangent of key 0
        sloped.values[9] = 1.0; // in-tangent of key 1
        let s: f32 = 0.25;
        let expected = 3.0 * s * s - 2.0 * s.powi(3)
            + 2.0 * (s.powi(3) - 2.0 * s * s + s)
            + 2.0 * (s.powi(3) - s * s);
        assert!((sloped.sample(0.5).x - expected).abs() < 1e-6);
        assert_eq!(sloped.sample(-1.0).x, 0.0);
        assert_eq!(sloped.sample(9.0).x, 1.0);
    }

    #[test]
    fn sample_keeps_rest_of_unanimated_properties() {
        let rest = [Trs {
            translation: Vec3::new(1.0, 2.0, 3.0),
            ..Trs::IDENTITY
        }];
        let c = clip(vec![track(
            Property::Scale,
            Interpolation::Step,
            &[0.0],
            &[2.0, 2.0, 2.0],
        )]);
        let mut out = [Trs::IDENTITY];
        c.sample(0.5, &rest, &mut out);
        assert_eq!(out[0].translation, rest[0].translation);
        assert_eq!(out[0].scale, Vec3::splat(2.0));
    }
}
