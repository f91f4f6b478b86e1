"""An info dict's numbers in a row of float64 slots, for SharedMemoryVectorEnv
(shared_vector.py): a worker writes each step's info into its row of a shared array, the
learner reads it back, or merges all rows at once into the arrays gymnasium's
VectorEnv._add_info would build (AsyncVectorEnv's infos), without pickling.

What fits a slot, exactly: Python float, int (|v| <= 2^53), bool, numpy scalars of float16/32/64,
(u)int8/16/32 and bool_, and tuples of Python floats (one slot each). Anything else is an
"extra" that the worker sends through its pipe (pickled) when present.
"""
import numpy as np

MAX_SLOTS = 32           # numeric info slots per worker; more go through the pipe

# numpy scalar types whose every value a float64 holds exactly
_EXACT_IN_FLOAT64 = {np.dtype(t).str for t in (np.float16, np.float32, np.float64, np.int8,
                                                 np.int16, np.int32, np.uint8, np.uint16,
                                                 np.uint32, np.bool_)}


def encode_info(info, slots):
    """(layout, extras): layout is a tuple of (key, kind, width), one per key in the info's
    order, kind "float", "int", "bool", a numpy dtype string, "tuple" (of Python floats,
    width = length) or "extra" (the value is in extras, to be pickled); the numeric values are
    written into `slots` (a float64 row) in layout order, each exact."""
    layout, extras, used = [], None, 0
    for key, value in info.items():
        kind, width = "extra", 0
        t = type(value)
        if t is float:
            kind, width = "float", 1
        elif t is bool:
            kind, width = "bool", 1
        elif t is int:
            if -2 ** 53 <= value <= 2 ** 53:
                kind, width = "int", 1
        elif t is tuple:
            if all(type(v) is float for v in value):
                kind, width = "tuple", len(value)
        elif isinstance(value, np.generic) and value.dtype.str in _EXACT_IN_FLOAT64:
            kind, width = value.dtype.str, 1
        if kind != "extra" and used + width > MAX_SLOTS:
            kind, width = "extra", 0
        if kind == "extra":
            if extras is None:
                extras = {}
            extras[key] = value
        elif width == 1:
            slots[used] = value
        elif width:
            slots[used:used + width] = value
        used += width
        layout.append((key, kind, width))
    return tuple(layout), extras


def decode_info(layout, slots, extras):
    """The info dict encode_info was given: same keys in the same order, same types."""
    info, at = {}, 0
    for key, kind, width in layout:
        if kind == "float":
            info[key] = float(slots[at])
        elif kind == "int":
            info[key] = int(slots[at])
        elif kind == "bool":
            info[key] = bool(slots[at])
        elif kind == "tuple":
            info[key] = tuple(slots[at:at + width].tolist())
        elif kind == "extra":
            info[key] = extras[key]
        else:
            info[key] = np.dtype(kind).type(slots[at])
        at += width
    return info


_ARRAY_DTYPE = {"float": np.dtype(float), "int": np.dtype(int), "bool": np.dtype(np.bool_)}


def merge_plan(layout):
    """For merge_same_layout: (key, "_" + key, kind's array dtype or None for a tuple,
    first slot, width) per key, and the slots used."""
    plan, at = [], 0
    for key, kind, width in layout:
        dtype = None if kind == "tuple" else _ARRAY_DTYPE.get(kind) or np.dtype(kind)
        plan.append((key, "_" + key, dtype, at, width))
        at += width
    return tuple(plan), at


def merge_same_layout(plan, used, slots):
    """The merged infos AsyncVectorEnv builds (gymnasium's VectorEnv._add_info) when every
    sub-environment's info has the same layout and no extras: one array per key, in key
    order, each followed by its all-True mask. (One copy of the slots, then rows of it.)"""
    n = slots.shape[0]
    columns = slots[:, :used].T.copy()
    masks = np.ones((len(plan), n), dtype=np.bool_)
    infos = {}
    for k, (key, mask_key, dtype, at, width) in enumerate(plan):
        if dtype is None:
            array = np.empty(n, dtype=object)
            for i, row in enumerate(columns[at:at + width].T.tolist()):
                array[i] = tuple(row)
        elif dtype.char == "d":
            array = columns[at]
        else:
            array = columns[at].astype(dtype)
        infos[key] = array
        infos[mask_key] = masks[k]
    return infos
