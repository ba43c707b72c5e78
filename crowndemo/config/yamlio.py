"""Reading YAML for presets: floats written without a dot (``1e-3``) are numbers, a key given
twice in one mapping is an error, and a syntax error names the file, line and column."""
from __future__ import annotations

import re
from typing import Any

import yaml

from .errors import PresetError

# YAML 1.1 (PyYAML) reads 1e-3 as a string: only 1.0e-3 is a float. Presets are full of
# lengths in metres, so accept the exponent form too.
_FLOAT = re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
    |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
    |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
    |[-+]?\.(?:inf|Inf|INF)
    |\.(?:nan|NaN|NAN))$""", re.X)


class _Loader(yaml.SafeLoader):
    pass


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT, list("-+0123456789."))


class DuplicateKey(yaml.YAMLError):
    def __init__(self, key, mark):
        super().__init__()
        self.key, self.mark = key, mark


def _mapping(loader: _Loader, node: yaml.MappingNode, deep: bool = False):
    loader.flatten_mapping(node)
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise DuplicateKey(key, key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)


def _where(mark) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""


def load_text(text: str, source: str) -> Any:
    """Parse YAML; a syntax error or a duplicated key becomes a PresetError naming ``source``."""
    try:
        return yaml.load(text, Loader=_Loader)
    except DuplicateKey as e:
        raise PresetError(source, str(e.key), why=f"key given twice in one mapping "
                          f"({_where(e.mark)})", allowed="each key once") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        problem = getattr(e, "problem", None) or str(e)
        where = f" at {_where(mark)}" if mark is not None else ""
        raise PresetError(source, None, why=f"not valid YAML{where}: {problem}") from None


def parse_scalar(text: str, source: str) -> Any:
    """A ``--set`` value: YAML (``7``, ``1e-3``, ``true``, ``water``, ``{rho: 1000}``);
    an empty value is null (restores the default)."""
    return load_text(text, source) if text.strip() else None


__all__ = ["load_text", "parse_scalar"]
