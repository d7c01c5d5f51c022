"""Checks of a hand-written system model file beyond its shape (docs/model.md): keys written
twice, the format version, definitions (unreadable lines, unknown field types, a field named
twice) and units of fields a known definition lacks. Each is an error at its line."""
from __future__ import annotations

from typing import Any, Iterable, List, Optional, Tuple

import yaml

from .errors import a_noun, did_you_mean
from .msgdef import PRIMITIVES, Registry, definition_lines
from .yamltags import duplicate_keys

VERSIONS = (1,)  # the model file formats this rubass reads


def duplicates(root: yaml.Node) -> List[Tuple[yaml.Node, str]]:
    """(the second key, why) for each key written twice in one mapping."""
    return [(second, f"key '{second.value}' is written twice in one mapping (first at {first.start_mark.line + 1}:"
                     f"{first.start_mark.column + 1}); YAML would keep only the last: remove one")
            for _, second, first in duplicate_keys(root)]


def version_problem(value: Any) -> Optional[str]:
    """Why a `rubass_model:` value is not a version this rubass reads (None: it is)."""
    if isinstance(value, bool) or not isinstance(value, int) or value not in VERSIONS:
        return (f"'rubass_model' is the model file's format version: {', '.join(map(str, VERSIONS))} is known "
                f"here, got {value!r} (a newer rubass may have written it)")
    return None


def definition_problems(type_name: str, text: str, defined: Iterable[str]) -> List[Tuple[int, str]]:
    """(line within the definition, why) for every line of `text` that cannot be read, names a
    field type that cannot exist, or names a field already named.

    A field type is a primitive, `Header`, a type of the same package written bare (`Cell`) or
    `package/Type`; types not defined in the file may be installed where the check runs, so
    they are accepted. A bare lower-case name is neither a primitive nor a message type (ROS
    types are CamelCase): `flaot32` is an error with a did-you-mean."""
    package = type_name.split("/")[0]
    own = sorted({t.split("/", 1)[1] for t in defined if t.startswith(package + "/")})
    out: List[Tuple[int, str]] = []
    seen = {}
    for number, raw, m in definition_lines(text):
        if m is None:
            out.append((number, f"{type_name}: line {number}: cannot read '{raw.strip()}'"))
            continue
        ftype, _, _, name, _ = m.groups()
        if ftype not in PRIMITIVES and "/" not in ftype and ftype != "Header" and ftype not in own \
                and not ftype[:1].isupper():
            hint = did_you_mean(ftype, sorted(PRIMITIVES) + own + ["Header"])
            out.append((number, f"{type_name}: line {number}: unknown field type '{ftype}'{hint} (a primitive such "
                                f"as float64, a message of package {package} written 'Type', or 'package/Type')"))
        if name in seen:
            out.append((number, f"{type_name}: line {number}: field '{name}' is named twice (first on line "
                                f"{seen[name]})"))
        seen.setdefault(name, number)
    return out


def unit_path_problem(registry: Registry, root: str, path: str) -> Optional[str]:
    """Why a dotted field path of a units table is not a field of `root` (arrays are crossed
    without an index); None when it is, or when a type on the way has no definition here."""
    current = root
    names = path.split(".")
    for i, name in enumerate(names):
        spec = registry.get(current)
        if spec is None:
            return None
        found = spec.get(name)
        done = ".".join(names[:i])
        if found is None:
            at = root if not done else f"'{done}' ({current})"
            return (f"{at} has no field '{name}'{did_you_mean(name, spec.names)} "
                    f"(its fields: {', '.join(spec.names) or 'none'})")
        if found.is_primitive and i + 1 < len(names):
            return f"'{'.'.join(names[:i + 1])}' is {a_noun(found.type)}, not a message: it has no field '{names[i + 1]}'"
        current = found.type
        if i + 1 == len(names) and (not found.is_primitive or found.type in ("string", "bool")):
            what = "a message" if not found.is_primitive else "not a number"
            return f"'{path}' is {a_noun(found.type + ('[]' if found.is_array else ''))}, {what}: it takes no unit"
    return None
