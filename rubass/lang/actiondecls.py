"""The checker's part for actions (LANGUAGE.md §9): the action libraries a spec imports or is given,
and its `action` declarations against them (duplicates, undefined actions, failed imports)."""
from __future__ import annotations

import os
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from . import ast
from .errors import Diagnostic, did_you_mean
from .library import ActionDef, load_library
from .paths import PathError, resolve
from .source import SourceSet, Span


class ActionDecls:
    """A mixin of the checker: it needs `spec`, `sources`, `diags`, `_unusable_libraries` and `error`."""

    spec: ast.Spec
    sources: SourceSet
    diags: List[Diagnostic]
    _unusable_libraries: List[str]
    error: Callable[[Span, str], None]

    def load_libraries(self, extra: Sequence[str]) -> Tuple[Dict[str, ActionDef], List[str]]:
        actions: Dict[str, ActionDef] = {}
        loaded: List[str] = []
        base = os.path.dirname(os.path.abspath(self.spec.file))
        wanted: List[Tuple[str, Span]] = []
        for d in self.spec.decls:
            if isinstance(d, ast.Import):
                try:
                    wanted.append((resolve(d.path, base), d.span))
                except PathError as exc:
                    self.error(d.span, f"cannot import '{d.path}': {exc}")
        for p in extra:  # given on the command line or in ~actions: relative to the working directory
            try:
                wanted.append((resolve(p, os.getcwd()), Span(p, 0, 0)))
            except PathError as exc:
                self.error(Span(p, 0, 0), f"cannot use the action library '{p}': {exc}")
                self._unusable_libraries.append(p)  # its actions are not "undefined": this error says why
        for path, span in wanted:
            if path in loaded:
                continue
            if span.line and not os.path.isfile(path):
                why = ("it is a directory" if os.path.isdir(path) else
                       "not a regular file" if os.path.exists(path) else "no such file")
                self.error(span, f"cannot import '{path}': {why}")
                continue
            lib, diags = load_library(path, self.sources)
            self.diags.extend(diags)
            if not lib and any(d.severity == "error" and not d.subject for d in diags):
                self._unusable_libraries.append(path)  # its own error says why; its actions are not "undefined"
            if self.sources.get(path) is not None:  # read, even if some actions were invalid
                loaded.append(path)
            for name, act in lib.items():
                if name in actions:
                    self.error(act.span, f"action '{name}' is defined again; first defined at {actions[name].span}")
                else:
                    actions[name] = act
        return actions, loaded

    def check_actions(self, library: Dict[str, ActionDef], loaded: List[str]) -> Dict[str, Span]:
        declared: Dict[str, Span] = {}
        for d in self.spec.decls:
            if not isinstance(d, ast.ActionDecl):
                continue
            for ident in d.names:
                if ident.name in declared:
                    self.error(ident.span, f"duplicate action '{ident.name}': already declared at "
                                           f"{declared[ident.name]}")  # duplicate names are errors (§9)
                    continue
                declared[ident.name] = ident.span
                if ident.name not in library and not self._broken_in_library(ident.name) \
                        and not self._unusable_libraries:
                    failed = self._failed_imports(loaded)
                    where = ("no action library is loaded: add 'import \"actions.yaml\";' or pass --actions"
                             if not loaded else "loaded: " + ", ".join(loaded))
                    if failed:  # the spec has an import: say that it failed, not that there is none
                        where = (f"{'its library' if len(failed) == 1 else 'its libraries'} "
                                 f"{', '.join(repr(f) for f in failed)} could not be loaded: see the error above"
                                 + (f"; loaded: {', '.join(loaded)}" if loaded else ""))
                    self.error(ident.span, f"action '{ident.name}' is not defined in any action library "
                                           f"({where}){did_you_mean(ident.name, library)}")
        return declared

    def _failed_imports(self, loaded: List[str]) -> List[str]:
        """The spec's imports (as written) that could not be loaded: a package not found, no such file."""
        base = os.path.dirname(os.path.abspath(self.spec.file))
        out: List[str] = []
        for d in self.spec.decls:
            if not isinstance(d, ast.Import):
                continue
            try:
                path: Optional[str] = resolve(d.path, base)
            except PathError:
                path = None
            if path not in loaded and path not in self._unusable_libraries and d.path not in out:
                out.append(d.path)
        return out

    def _broken_in_library(self, name: str) -> bool:
        """True when a library defines `name` but its definition had errors (already reported)."""
        return any(d.subject == name for d in self.diags)
