//! numpy arrays in and out: every input array is checked for its shape, its kind of number
//! and its values (finite, indices in range) with a `ValueError` naming the argument, then
//! copied into the types of the Rust crates, so that the work runs without the GIL.

use glam::{Mat4, Vec3};
use numpy::{
    Element, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// What kind of numbers an argument holds.
#[derive(Clone, Copy)]
enum Kind {
    /// float32 or float64 (read as f64).
    Float,
    /// Any integer type (read as i64).
    Integer,
}

/// An argument's values, row-major, with its shape.
struct Values<T> {
    data: Vec<T>,
    shape: Vec<usize>,
}

/// Reads `value` (a numpy array or anything `numpy.asarray` takes) as an array of
/// `shape` (`None`: any length; shown as the letter of `letters` at that axis) holding
/// numbers of `kind`, converted to `T` (f64 or i64).
fn read<T: Element + Copy>(
    value: &Bound<'_, PyAny>,
    name: &str,
    shape: &[Option<usize>],
    letters: &str,
    kind: Kind,
) -> PyResult<Values<T>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let array = numpy.call_method1("asarray", (value,))?;
    let untyped = array.cast::<PyUntypedArray>()?;
    let expected: Vec<String> = shape
        .iter()
        .zip(letters.chars())
        .map(|(n, letter)| n.map_or(letter.to_string(), |n| n.to_string()))
        .collect();
    let actual = untyped.shape();
    let fits = actual.len() == shape.len()
        && actual
            .iter()
            .zip(shape)
            .all(|(&a, n)| n.is_none_or(|n| a == n));
    if !fits {
        let actual: Vec<String> = actual.iter().map(usize::to_string).collect();
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({}), got ({})",
            expected.join(", "),
            actual.join(", ")
        )));
    }
    let dtype = untyped.dtype();
    let ok = match kind {
        Kind::Float => dtype.kind() == b'f',
        Kind::Integer => matches!(dtype.kind(), b'i' | b'u'),
    };
    if !ok {
        let wanted = match kind {
            Kind::Float => "floats (float32 or float64)",
            Kind::Integer => "integers",
        };
        return Err(PyValueError::new_err(format!(
            "{name} must hold {wanted}, got {}",
            dtype.str()?
        )));
    }
    if let Kind::Integer = kind {
        // Unsigned 64-bit values above i64::MAX would wrap: refuse them by value.
        if dtype.kind() == b'u' && dtype.itemsize() == 8 && untyped.len() > 0 {
            let max: u64 = array.call_method0("max")?.extract()?;
            if max > i64::MAX as u64 {
                return Err(PyValueError::new_err(format!(
                    "{name} holds {max}, too large for an index"
                )));
            }
        }
    }
    let converted = numpy.call_method1("ascontiguousarray", (&array, numpy::dtype::<T>(py)))?;
    let typed = converted.cast::<PyArrayDyn<T>>()?.readonly();
    Ok(Values {
        data: typed.as_slice()?.to_vec(),
        shape: actual.to_vec(),
    })
}

/// `(N, 3)` floats, every value finite, as f32 points.
pub fn points(value: &Bound<'_, PyAny>, name: &str, letter: char) -> PyResult<Vec<Vec3>> {
    let values = read::<f64>(
        value,
        name,
        &[None, Some(3)],
        &format!("{letter}3"),
        Kind::Float,
    )?;
    values
        .data
        .chunks_exact(3)
        .enumerate()
        .map(|(i, p)| finite_point(p, name, i))
        .collect()
}

fn finite_point(p: &[f64], name: &str, row: usize) -> PyResult<Vec3> {
    let point = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    if point.is_finite() {
        Ok(point)
    } else {
        Err(PyValueError::new_err(format!(
            "{name}[{row}] is not finite: {p:?}"
        )))
    }
}

/// `(J, 3)` floats where a row is either finite or all NaN (`None`).
pub fn optional_points(
    value: &Bound<'_, PyAny>,
    name: &str,
    count: usize,
) -> PyResult<Vec<Option<Vec3>>> {
    let values = read::<f64>(value, name, &[Some(count), Some(3)], "J3", Kind::Float)?;
    values
        .data
        .chunks_exact(3)
        .enumerate()
        .map(|(i, p)| {
            if p.iter().all(|x| x.is_nan()) {
                Ok(None)
            } else {
                finite_point(p, name, i).map(Some)
            }
        })
        .collect()
}

/// `(F, 3)` integers, each in `0..vertex_count`.
pub fn triangles(value: &Bound<'_, PyAny>, vertex_count: usize) -> PyResult<Vec<[u32; 3]>> {
    let values = read::<i64>(value, "triangles", &[None, Some(3)], "F3", Kind::Integer)?;
    values
        .data
        .chunks_exact(3)
        .enumerate()
        .map(|(f, t)| {
            let mut out = [0u32; 3];
            for (slot, &v) in out.iter_mut().zip(t) {
                *slot = index(v, vertex_count).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "triangles[{f}] uses vertex {v}, but there are {vertex_count} vertices"
                    ))
                })?;
            }
            Ok(out)
        })
        .collect()
}

/// `v` as an index into `0..count`.
fn index(v: i64, count: usize) -> Option<u32> {
    u32::try_from(v).ok().filter(|&v| (v as usize) < count)
}

/// `(J,)` integers: -1 for a root ([`atlas_skin_runtime::NO_PARENT`]), else a joint index.
pub fn parents(value: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<u32>> {
    let values = read::<i64>(value, "parents", &[Some(count)], "J", Kind::Integer)?;
    values
        .data
        .iter()
        .enumerate()
        .map(|(j, &p)| match p {
            -1 => Ok(atlas_skin_runtime::NO_PARENT),
            _ => index(p, count).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "parents[{j}] is {p}: neither -1 (a root) nor a joint index below {count}"
                ))
            }),
        })
        .collect()
}

/// Skinning weights given as `(V, K)` joint indices and `(V, K)` weights (zero weights
/// are left out), every index below `joint_count`, every weight finite.
pub fn vertex_weights(
    indices: &Bound<'_, PyAny>,
    weights: &Bound<'_, PyAny>,
    vertex_count: usize,
    joint_count: usize,
) -> PyResult<atlas_skin_runtime::VertexWeights> {
    let indices = read::<i64>(
        indices,
        "indices",
        &[Some(vertex_count), None],
        "VK",
        Kind::Integer,
    )?;
    let k = indices.shape[1];
    let weights = read::<f64>(
        weights,
        "weights",
        &[Some(vertex_count), Some(k)],
        "VK",
        Kind::Float,
    )?;
    if let Some(i) = weights.data.iter().position(|w| !w.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "weights[{}, {}] is not finite: {}",
            i / k.max(1),
            i % k.max(1),
            weights.data[i]
        )));
    }
    if let Some(i) = indices
        .data
        .iter()
        .position(|&j| index(j, joint_count).is_none())
    {
        return Err(PyValueError::new_err(format!(
            "indices[{}, {}] is {}, but the palette has {joint_count} joints",
            i / k,
            i % k,
            indices.data[i]
        )));
    }
    let rows = (0..vertex_count).map(|v| {
        (0..k)
            .map(move |i| v * k + i)
            .filter(|&i| weights.data[i] != 0.0)
            .map(|i| (indices.data[i] as u32, weights.data[i] as f32))
            .collect::<Vec<_>>()
    });
    Ok(atlas_skin_runtime::VertexWeights::from_rows(rows))
}

/// `(J, 4, 4)` finite matrices acting on column vectors (`p' = M @ [x, y, z, 1]`).
pub fn palette(value: &Bound<'_, PyAny>) -> PyResult<Vec<Mat4>> {
    matrices(value, "palette", None)
}

/// `(count, 4, 4)` (any count when `None`) finite matrices acting on column vectors, the
/// argument named `name` in messages.
pub fn matrices(value: &Bound<'_, PyAny>, name: &str, count: Option<usize>) -> PyResult<Vec<Mat4>> {
    let values = read::<f64>(value, name, &[count, Some(4), Some(4)], "J44", Kind::Float)?;
    values
        .data
        .chunks_exact(16)
        .enumerate()
        .map(|(j, m)| {
            let rows: Vec<f32> = m.iter().map(|&x| x as f32).collect();
            let matrix = Mat4::from_cols_slice(&rows).transpose();
            if matrix.is_finite() {
                Ok(matrix)
            } else {
                Err(PyValueError::new_err(format!("{name}[{j}] is not finite")))
            }
        })
        .collect()
}

/// `(N, 3)` float32 array of points.
pub fn points_array<'py>(py: Python<'py>, points: &[Vec3]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat: Vec<f32> = points.iter().flat_map(|p| p.to_array()).collect();
    PyArray1::from_vec(py, flat).reshape([points.len(), 3])
}

/// `(N, C)` array from rows of `C` values.
pub fn rows_array<'py, T: Element + Copy, const C: usize>(
    py: Python<'py>,
    rows: &[[T; C]],
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), C])
}

/// Joint indices and weights, `(V, K)` each.
pub type WeightArrays<'py> = (Bound<'py, PyArray2<u32>>, Bound<'py, PyArray2<f32>>);

/// Weights as two `(V, K)` arrays, joint indices (uint32) and weights (float32), each row
/// in the order stored, padded with joint 0 and weight 0.
pub fn weights_arrays<'py>(
    py: Python<'py>,
    weights: &atlas_skin_runtime::VertexWeights,
    k: usize,
) -> PyResult<WeightArrays<'py>> {
    let v = weights.vertex_count();
    let mut joints = vec![0u32; v * k];
    let mut values = vec![0f32; v * k];
    for vertex in 0..v {
        for (i, (j, w)) in weights.row(vertex).take(k).enumerate() {
            joints[vertex * k + i] = j;
            values[vertex * k + i] = w;
        }
    }
    Ok((
        PyArray1::from_vec(py, joints).reshape([v, k])?,
        PyArray1::from_vec(py, values).reshape([v, k])?,
    ))
}

/// `(J, 4, 4)` float32 array of matrices, rows as numpy indexes them (`M[row, column]`).
pub fn matrices_array<'py>(py: Python<'py>, matrices: &[Mat4]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = matrices
        .iter()
        .flat_map(|m| m.transpose().to_cols_array())
        .collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([matrices.len(), 4, 4])?
        .into_any())
}
