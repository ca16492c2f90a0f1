"""Input checks the geometry APIs share: numeric arrays and index arrays, with messages that say what is wrong."""
import numpy as np


def numeric_array(values, name, dtype=np.float64):
    """``values`` as an array of ``dtype``; ValueError naming ``name`` when it cannot be one."""
    try:
        return np.asarray(values, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array: {exc}") from None


def nonfinite_rows(array):
    """Indices of the rows of a 2D array that hold a NaN or an infinity; the whole-array test is far faster, so rows
    are looked at only when one is bad."""
    if np.isfinite(array).all():
        return np.zeros(0, np.int64)
    return np.flatnonzero(~np.isfinite(array).all(axis=1))


def point_array(values, columns, name):
    """``values`` as a C-contiguous (N, ``columns``) float64 array of finite numbers ((0, columns) when empty);
    ValueError naming ``name`` and the first bad row otherwise."""
    array = numeric_array(values, name)
    if array.size == 0:
        return np.zeros((0, columns), np.float64)
    if array.ndim != 2 or array.shape[1] != columns:
        raise ValueError(f"{name} must have shape (N, {columns}), got {array.shape}")
    bad = nonfinite_rows(array)
    if bad.size:
        raise ValueError(f"{name} must be finite; row {bad[0]} is {array[bad[0]].tolist()}")
    return np.ascontiguousarray(array)


def index_array(values, columns, count, *, name, item, target, dtype):
    """Rows of ``columns`` indices into ``count`` things, as a contiguous ``dtype`` array ((0, columns) if empty).

    Whole-valued floats are accepted; anything else non-integer, a wrong shape, or an index outside 0..count-1 is a
    ValueError, e.g. "segment 3 [0, 9] indexes outside the 5 points" (``name`` "segments", ``item`` "segment",
    ``target`` ("point", "points")).
    """
    raw = np.asarray(values)
    if raw.size == 0:
        return np.zeros((0, columns), dtype)
    if raw.dtype.kind not in "iu":
        if raw.dtype.kind == "f" and np.isfinite(raw).all() and (raw == np.round(raw)).all():
            raw = raw.astype(np.int64)
        else:
            raise ValueError(f"{name} must hold integer {target[0]} indices, got dtype {raw.dtype}")
    if raw.ndim != 2 or raw.shape[1] != columns:
        raise ValueError(f"{name} must have shape (M, {columns}), got {raw.shape}")
    if raw.min() < 0 or raw.max() >= count:
        bad = int(np.flatnonzero(((raw < 0) | (raw >= count)).any(axis=1))[0])
        raise ValueError(f"{item} {bad} {raw[bad].tolist()} indexes outside the {count} {target[1]}")
    return np.ascontiguousarray(raw, dtype=dtype)


def column_bounds(points):
    """(2, D) float64: the minimum and maximum of each column of (N, D) ``points`` — per column, as numpy's axis-0
    reduction over an (N, 3) array is ~40x slower."""
    columns = np.asarray(points).T
    return np.array([[column.min() for column in columns], [column.max() for column in columns]])


def concatenated_ranges(starts, counts):
    """``arange(starts[k], starts[k] + counts[k])`` for every k, end to end, without a Python loop."""
    starts, counts = np.asarray(starts), np.asarray(counts)
    return np.repeat(starts - (np.cumsum(counts) - counts), counts) + np.arange(counts.sum())
