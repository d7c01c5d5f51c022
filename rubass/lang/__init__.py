"""The RuBaSS language: grammar, AST, checker, formatter. Imports no ROS."""
from .errors import Diagnostic, RubassError, SpecError
from .fmt import format_expr, format_spec
from .grammar import parse_source, parse_text
from .loader import check_source, check_text, load_spec
from .model import CheckedSpec

__all__ = ["Diagnostic", "RubassError", "SpecError", "format_expr", "format_spec", "parse_source",
           "parse_text", "check_source", "check_text", "load_spec", "CheckedSpec"]
