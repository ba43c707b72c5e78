"""Reading YAML for presets: floats written without a dot (``1e-3``) are numbers, a key given
twice in one mapping is an error, and a syntax error names the file, line and column."""
from __future__ import annotations

import re
from typing import Any, Optional, Tuple

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
    def __init__(self, key, value, mark, mapping):
        super().__init__()
        self.key, self.value, self.mark, self.mapping = key, value, mark, mapping


def _mapping(loader: _Loader, node: yaml.MappingNode, deep: bool = False):
    loader.flatten_mapping(node)
    seen = set()
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise DuplicateKey(key, loader.construct_object(value_node, deep=True),
                               key_node.start_mark, node)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)


def _where(mark) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""


def _path_to(node, target, path: Tuple = ()) -> Optional[Tuple]:
    """The key path from ``node`` down to the mapping node ``target``, or None."""
    if node is target:
        return path
    if isinstance(node, yaml.MappingNode):
        children = [(getattr(k, "value", "?"), v) for k, v in node.value]
    elif isinstance(node, yaml.SequenceNode):
        children = list(enumerate(node.value))
    else:
        return None
    for key, child in children:
        found = _path_to(child, target, path + (key,))
        if found is not None:
            return found
    return None


def load_text(text: str, source: str, prefix: Tuple = ()) -> Any:
    """Parse YAML; a syntax error, a duplicated key, nesting deeper than Python recurses or a
    number it cannot convert becomes a PresetError naming ``source`` (and a duplicated key's
    path, below ``prefix``: where the text sits in a preset)."""
    loader = _Loader(text)
    root = None
    try:
        root = loader.get_single_node()
        return loader.construct_document(root) if root is not None else None
    except DuplicateKey as e:
        path = prefix + (_path_to(root, e.mapping) or ()) + (e.key,)
        raise PresetError(source, ".".join(str(p) for p in path), e.value,
                          f"key given twice in one mapping ({_where(e.mark)})",
                          allowed="each key once") from None
    except RecursionError:
        raise PresetError(source, None, why="not valid YAML: nested too deeply") from None
    except ValueError as e:      # an integer longer than Python converts (4300 digits)
        raise PresetError(source, None,
                          why=f"not valid YAML: a value it cannot read ({str(e).split(';')[0]})"
                          ) from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        problem = getattr(e, "problem", None) or str(e)
        where = f" at {_where(mark)}" if mark is not None else ""
        raise PresetError(source, None, why=f"not valid YAML{where}: {problem}") from None
    finally:
        loader.dispose()


def parse_scalar(text: str, source: str, prefix: Tuple = ()) -> Any:
    """A ``--set`` value: YAML (``7``, ``1e-3``, ``true``, ``water``, ``{rho: 1000}``);
    an empty value is null (restores the default). ``prefix``: the key path it sets."""
    return load_text(text, source, prefix) if text.strip() else None


__all__ = ["load_text", "parse_scalar"]
