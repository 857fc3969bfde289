"""LTLf objectives as minimal DFAs (the only package that knows how to compile LTLf)."""

from .compile import COMPILER_VERSION, cache_dir, compile_ltlf
from .dfa import Automaton
from .draw import image_format, to_dot, write_image
from .ltlf import LTLfSyntaxError, parse

__all__ = [
    "Automaton", "compile_ltlf", "cache_dir", "COMPILER_VERSION", "LTLfSyntaxError", "parse",
    "image_format", "to_dot", "write_image",
]
