"""Installed message and service definitions, and the checks a checked spec gets against the
system after its own: action libraries against definitions, topics and nodes a model lacks.
Light: the monitor runs these at start and at every reload."""
from __future__ import annotations

import importlib
import importlib.util
import os
from typing import Dict, Iterable, List, Optional, Sequence, Tuple

from ..lang import ast
from ..lang.errors import Diagnostic, SpecError, in_text_order
from ..lang.grammar import parse_source
from ..lang.library import ActionDef, load_library
from ..lang.paths import PathError, resolve
from ..lang.source import SourceSet
from ..lang.sourcefile import read_source
from ..lang.libcheck import check_library_types, check_publish_topics, library_types, plugin_module_warnings
from ..lang.model import CheckedSpec
from ..lang.msgdef import Registry, parse_full
from ..lang.stdlib import is_standard_library
from ..lang.sysmodel import SystemModel, graph_warnings


def _importable(type_name: str) -> bool:
    """Whether looking the type up may import its package: never a standard library module
    (importing 'antigravity' opens a browser, and a library is not to run code)."""
    return not is_standard_library(type_name.split("/")[0])


def top_level_found(name: str) -> bool:
    """Whether this Python finds a top-level package or module: looked up on the path, not imported (for a
    top-level name importlib.util.find_spec runs none of its code, so a library still runs nothing)."""
    if not name.isidentifier():
        return False
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):  # a module in sys.modules without a spec, a broken finder
        return False


def add_installed(registry: Registry, msg_types: Iterable[str], srv_types: Iterable[str] = ()) -> None:
    """Add the installed definitions of these message and service types (and what they use)."""
    import roslib.message

    for t in msg_types:
        if registry.get(t) is not None or not _importable(t):
            continue
        try:
            cls = roslib.message.get_message_class(t)
            if cls is not None:
                registry.add_full(t, cls._full_text)
        except Exception:  # not installed, a broken package, a bad name: unknown here
            continue
    for t in srv_types:
        if t in registry.services or not _importable(t):
            continue
        try:
            cls = roslib.message.get_service_class(t)
            if cls is None:
                continue
            req = parse_full(t + "Request", cls._request_class._full_text)
            resp = parse_full(t + "Response", cls._response_class._full_text)
        except Exception:
            continue
        for spec in list(req.values()) + list(resp.values()):
            registry.add(spec)
        registry.add_service(t, req[t + "Request"], resp[t + "Response"])


def installed_names(registry: Registry, msgs: Iterable[str], srvs: Iterable[str]) -> Tuple[List[str], List[str]]:
    """The installed message and service types of the packages of those not found, for a
    did-you-mean ('std_srvs/Trigerr': 'std_srvs/Trigger', not another type the library names)."""
    out: Dict[str, List[str]] = {"msg": [], "srv": []}
    wanted = {(t.split("/")[0], "msg") for t in msgs if registry.get(t) is None} | \
             {(t.split("/")[0], "srv") for t in srvs if t not in registry.services}
    for package, kind in sorted(wanted):
        if not package.isidentifier() or not _importable(package + "/"):
            continue
        try:
            module = importlib.import_module(f"{package}.{kind}")
        except Exception:  # no such package here, or a broken one: nothing to suggest
            continue
        for name in dir(module):
            cls = getattr(module, name, None)
            type_name = getattr(cls, "_type", None)
            if isinstance(type_name, str) and (kind == "msg") != hasattr(cls, "_request_class"):
                out[kind].append(type_name)
    return out["msg"], out["srv"]


def try_installed(registry: Registry, msgs: Iterable[str], srvs: Iterable[str]) -> bool:
    """add_installed, when ROS Python is here; False when it is not."""
    try:
        add_installed(registry, msgs, srvs)
        return True
    except ImportError:  # no ROS Python here: only the model's own definitions
        return False


def after_check(checked: CheckedSpec, model: Optional[SystemModel]) -> Tuple[List[Diagnostic], List[Diagnostic]]:
    """(errors, warnings) of the checks against the system: the spec's topics and nodes the
    model lacks (warnings), custom plugins whose package this Python cannot find (warnings), and
    its action libraries against message definitions (errors)."""
    warnings = graph_warnings(checked.spec, model) if model is not None else []
    warnings += plugin_module_warnings(checked.actions, top_level_found)  # the monitor would refuse to start
    return library_errors(checked.actions, checked.sources, model), warnings


def library_errors(actions: Dict[str, ActionDef], sources: SourceSet, model: Optional[SystemModel]) -> List[Diagnostic]:
    """Publish and service actions against the model's definitions and the installed ones."""
    registry = Registry()
    if model is not None:
        for spec in model.registry.types.values():
            registry.add(spec)
    msgs, srvs = library_types(actions)
    installed = try_installed(registry, msgs, srvs)
    if not installed and model is None:
        return []  # nothing to check against
    where = " or ".join(([model.source] if model is not None else []) +
                        (["the message packages installed here"] if installed else []))
    known, known_services = installed_names(registry, msgs, srvs) if installed else ([], [])
    errors = check_library_types(actions, sources, registry, where, known, known_services)
    if model is not None:
        errors += check_publish_topics(actions, sources, model.topics, model.source)
    return errors


def failed_check(exc: SpecError, path: str, extra: Sequence[str], model: Optional[SystemModel] = None
                 ) -> List[Tuple[Diagnostic, Optional[SourceSet]]]:
    """Everything wrong with a spec that did not check, in the order of the text, each with the sources
    to render it against: its errors and warnings, and its libraries' errors against the installed
    definitions (after_failed_check), so that `rubass check`, the monitor's start and a reload all
    report every error in one run."""
    lib_errors, warnings, lib_sources = after_failed_check(path, extra, model)
    out: List[Tuple[Diagnostic, Optional[SourceSet]]] = []
    for d in in_text_order(exc.in_order() + warnings + lib_errors):  # a model's warnings in their place
        known = exc.sources is not None and exc.sources.get(d.span.file) is not None
        out.append((d, exc.sources if known else lib_sources))
    return out


def render_failed_check(exc: SpecError, path: str, extra: Sequence[str]) -> str:
    """failed_check as the text the monitor logs (as `rubass check` prints it)."""
    return "\n".join(d.render(sources) for d, sources in failed_check(exc, path, extra))


def after_failed_check(path: str, extra: Sequence[str],
                       model: Optional[SystemModel]) -> Tuple[List[Diagnostic], List[Diagnostic], SourceSet]:
    """after_check for a spec that did not check, so that everything is reported in one run:
    (library errors, topic and node warnings, their sources); nothing when the spec cannot be
    parsed. A library with errors of its own (reported already) has its valid actions checked."""
    sources = SourceSet()
    src, _ = read_source(path)
    if src is None:
        return [], [], sources
    sources.add(src)
    try:
        spec = parse_source(src)
        base = os.path.dirname(os.path.abspath(path))
        files = [resolve(d.path, base) for d in spec.decls if isinstance(d, ast.Import)] \
            + [resolve(p, os.getcwd()) for p in extra]
    except (SpecError, PathError):
        return [], [], sources
    warnings = graph_warnings(spec, model) if model is not None else []
    actions: Dict[str, ActionDef] = {}
    for f in files:
        if not os.path.isfile(f):
            continue
        lib, _ = load_library(f, sources)  # its own errors are reported already; check its valid actions
        actions.update(lib)
    warnings += plugin_module_warnings(actions, top_level_found)
    return library_errors(actions, sources, model), warnings, sources
