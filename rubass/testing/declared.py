"""The system model a test file gives: the types its topics declare (with their standard REP 103
units), besides the `model:` it names, so the spec is checked as `rubass check --bag` checks it."""
from __future__ import annotations

import dataclasses
import os
from typing import Any, Dict, List, Optional, Set, Tuple

from ..lang.ast import PathElem
from ..lang.fieldmodel import FieldInfo
from ..lang.msgdef import DefinitionError, Registry
from ..lang.sysmodel import SystemModel, norm_topic
from .cases import Case, TestFile


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


def _types(tf: TestFile) -> Tuple[Dict[str, Any], Set[str]]:
    """The message class the tests give each topic (the first one's), and the topics two tests type
    differently."""
    types: Dict[str, Any] = {}
    twice: Set[str] = set()
    for case in tf.cases:
        for topic, t in case.topics.items():
            name = norm_topic(topic)
            if name in types and types[name]._type != t.cls._type:
                twice.add(name)
            types.setdefault(name, t.cls)
    return types, twice


def declared_model(tf: TestFile, case: Optional[Case] = None) -> Optional[DeclaredModel]:
    """The model to check the spec of `tf` against: its `model:` (types it does not define filled from
    the installed ones, as `rubass check --model` does) plus every topic a test declares with a type the
    model lacks; a topic two tests give two types is left unknown, or, with `case`, has the type that
    test gives it. None when there is nothing to know. The file's own model is not changed."""
    types, twice = _types(tf)
    if case is not None:
        for topic, t in case.topics.items():
            if norm_topic(topic) in twice:
                types[norm_topic(topic)] = t.cls
        twice = twice - {norm_topic(topic) for topic in case.topics}
    model = tf.model
    if model is None:
        if not types:
            return None
        model = SystemModel({}, None, source=f"the topic types {os.path.basename(tf.path)} declares")
    else:
        from ..ros.libtypes import try_installed

        model = dataclasses.replace(model, topics=dict(model.topics))  # the declared types are this one's
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


def per_test_models(tf: TestFile) -> List[Tuple[Case, DeclaredModel]]:
    """For a file whose tests give one topic different types: each distinct combination of the types its
    tests give those topics, with the first test that gives it, and the model of that test's types (the
    spec is checked against each, as each test's messages are what the spec reads in it)."""
    _, twice = _types(tf)
    seen: Set[Tuple[Tuple[str, str], ...]] = set()
    out = []
    for case in tf.cases:
        key = tuple(sorted((norm_topic(n), t.cls._type) for n, t in case.topics.items() if norm_topic(n) in twice))
        if key and key not in seen:
            seen.add(key)
            model = declared_model(tf, case)
            if model is not None:
                out.append((case, model))
    return out
