"""The system model a test file gives: the types its topics declare (with their standard REP 103
units), besides the `model:` it names, so the spec is checked as `rubass check --bag` checks it."""
from __future__ import annotations

import os
from typing import Any, Dict, Optional, Set, Tuple

from ..lang.ast import PathElem
from ..lang.fieldmodel import FieldInfo
from ..lang.msgdef import DefinitionError, Registry
from ..lang.sysmodel import SystemModel, norm_topic
from .cases import TestFile


class DeclaredModel:
    """A SystemModel whose declared topics leave a field their type lacks to the runner, which says it
    at the test's topic line (the spec or the declared type is wrong, and the test shows which type it
    means); kinds, units and what only the model sees (an index past a fixed-size array) are the model's."""

    def __init__(self, model: SystemModel, declared: Dict[str, Any]) -> None:
        self.model, self.declared = model, declared  # declared: topic -> the message class the test gives

    def field(self, topic: str, path: Tuple[PathElem, ...]) -> Optional[FieldInfo]:
        from ..ros.msgtypes import check_path

        info = self.model.field(topic, path)
        cls = self.declared.get(norm_topic(topic))
        if info is not None and info.kind == "missing" and cls is not None:
            plain = []
            for p in path:  # as the runner checks it: up to a slice or [*]
                if not isinstance(p, (str, int)):
                    break
                plain.append(p)
            if check_path(cls, tuple(plain)):
                return None
        return info

    def has_stamp(self, topic: str) -> Optional[bool]:
        return self.model.has_stamp(topic)


def _add_class(registry: Registry, cls: Any) -> None:
    """The definitions of a message class (installed, or built from a model) and of the types it uses."""
    type_name = getattr(cls, "_type", "")
    if not type_name or registry.get(type_name) is not None:
        return
    try:
        registry.add_full(type_name, cls._full_text)
    except (DefinitionError, AttributeError):  # a definition the parser cannot read: its fields stay unknown
        pass


def declared_model(tf: TestFile) -> Optional[DeclaredModel]:
    """The model to check the spec of `tf` against: its `model:` (types it does not define filled from
    the installed ones, as `rubass check --model` does) plus every topic a test declares with a type the
    model lacks; a topic two tests give two types is left unknown. None when there is nothing to know."""
    types: Dict[str, Any] = {}
    twice: Set[str] = set()
    for case in tf.cases:
        for topic, t in case.topics.items():
            name = norm_topic(topic)
            if name in types and types[name]._type != t.cls._type:
                twice.add(name)
            types.setdefault(name, t.cls)
    model = tf.model
    if model is None:
        if not types:
            return None
        model = SystemModel({}, None, source=f"the topic types {os.path.basename(tf.path)} declares")
    else:
        from ..ros.libtypes import try_installed

        undefined = model.undefined_types()
        if undefined:
            try_installed(model.registry, undefined, ())
    declared = {}
    for name, cls in types.items():
        if name in twice or model.type_of(name) is not None:
            continue
        model.topics[name] = cls._type
        _add_class(model.registry, cls)
        declared[name] = cls
    return DeclaredModel(model, declared)
