"""A spec's field path resolved against message definitions: its kind and, from the unit
tables, its dimension (the FieldInfo the checker asks a system model for)."""
from __future__ import annotations

from typing import Dict, List, Optional, Sequence, Tuple

from .ast import PathElem, Slice, path_suffix
from .errors import a_noun, did_you_mean
from .fieldmodel import FieldInfo
from .msgdef import FieldDef, Registry
from .units import TIME, Dimension

UnitTable = Dict[str, Dict[str, Dimension]]  # type -> {dotted field path -> dimension}


def _prim_kind(ftype: str) -> str:
    if ftype == "bool":
        return "bool"
    if ftype == "string":
        return "str"
    return "num"  # integers, floats, char, byte, time, duration


def resolve(registry: Registry, root: str, path: Sequence[PathElem], tables: Sequence[UnitTable] = (),
            topic_units: Optional[Dict[str, Dimension]] = None) -> Optional[FieldInfo]:
    """The FieldInfo of `path` in messages of type `root`; None when a type on the way is not
    known (nothing can be said). `tables` are searched in order, the last hit winning;
    `topic_units` (dotted paths from the root) override them all."""
    spec = registry.get(root)
    if spec is None:
        return None
    anchors: List[Tuple[str, List[str]]] = [(root, [])]
    current: Optional[FieldDef] = None  # None: at the root message
    in_array = False  # `current` is an array not yet indexed
    mapped = False  # a slice or [*] was crossed: the result is one value per element
    dim: Optional[Dimension] = None
    done: Tuple[PathElem, ...] = ()
    for elem in path:
        where = f"'{path_suffix(done).lstrip('.')}'"
        if isinstance(elem, (int, Slice)):
            if not in_array:
                what = root if current is None else f"a {current.type}"
                return FieldInfo("missing", why=f"{where} is not an array (it is {what}): it cannot be indexed"
                                 if done else f"a {root} message is not an array")
            in_array, mapped = False, mapped or isinstance(elem, Slice)
            done += (elem,)
            continue
        if in_array:
            assert current is not None
            return FieldInfo("missing", why=f"{where} is an array ({current.type}[]): index it, e.g. "
                                            f"'{path_suffix(done + (0, elem)).lstrip('.')}'")
        if current is not None and current.is_primitive:
            return FieldInfo("missing", why=f"{where} is {a_noun(current.type)}, not a message: it has no field '{elem}'")
        owner = root if current is None else current.type
        spec = registry.get(owner)
        if spec is None:
            return None
        found = spec.get(elem)
        if found is None:
            at = owner if current is None else f"{where} ({owner})"
            hint = _one_level_down(registry, spec.fields, done, elem) or did_you_mean(elem, spec.names)
            return FieldInfo("missing", why=f"{at} has no field '{elem}'{hint} "
                                            f"(its fields: {', '.join(spec.names) or 'none'})")
        current, in_array = found, found.is_array
        done += (elem,)
        for anchor in anchors:
            anchor[1].append(elem)
            for table in tables:
                hit = table.get(anchor[0], {}).get(".".join(anchor[1]))
                if hit is not None:
                    dim = hit
        if topic_units:
            hit = topic_units.get(".".join(anchors[0][1]))
            if hit is not None:
                dim = hit
        if not found.is_primitive:
            anchors.append((found.type, []))
    if current is None:
        return FieldInfo("msg", why=f"it is {a_noun(root)} (fields: {', '.join(_names(registry, root))})")
    if current.type in ("time", "duration"):
        dim = TIME
    if in_array:
        return FieldInfo("array", dim, why=f"{current.type}[{current.length if current.length is not None else ''}]",
                         elem_kind="msg" if not current.is_primitive else _prim_kind(current.type))
    if not current.is_primitive:
        return FieldInfo("msg", why=f"it is {a_noun(current.type)} (fields: {', '.join(_names(registry, current.type))})")
    kind = _prim_kind(current.type)
    if mapped:
        return FieldInfo("array", dim if kind == "num" else None, elem_kind=kind)
    return FieldInfo(kind, dim if kind == "num" else None)


def _one_level_down(registry: Registry, fields: Sequence[FieldDef], done: Tuple[PathElem, ...], elem: str) -> str:
    """"; did you mean 'twist.twist.linear'?" when a field of the message has the field asked for."""
    for f in fields:
        inner = registry.get(f.type) if not f.is_primitive and not f.is_array else None
        if inner is not None and inner.get(elem) is not None:
            return f"; did you mean '{path_suffix(done + (f.name, elem)).lstrip('.')}'?"
    return ""


def _names(registry: Registry, type_name: str) -> List[str]:
    spec = registry.get(type_name)
    return spec.names if spec is not None else ["?"]


def has_stamp(registry: Registry, root: str) -> Optional[bool]:
    """Whether messages of `root` carry header.stamp; None when the type is unknown."""
    spec = registry.get(root)
    if spec is None:
        return None
    header = spec.get("header")
    return header is not None and header.type == "std_msgs/Header" and not header.is_array
