"""Finding and loading presets: a preset is ``presets/NAME.yaml`` (or any YAML file given by
path); ``extends: OTHER`` loads OTHER first (a preset name, or a path relative to the file that
extends it) and deep-merges this file onto it.

The presets folder is ``presets/`` at the repository root, next to the ``crowndemo`` package;
``$CROWNDEMO_PRESETS`` names another folder (an error when it is none). Files whose name
starts with ``_`` are not listed (bases meant only to be extended) but can still be named.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Tuple

from .errors import PresetError, did_you_mean
from .merge import DEFAULT_SOURCE, SET_SOURCE, Origin, deep_merge, origin_of
from .yamlio import load_text

SUFFIXES = (".yaml", ".yml")
MAX_DEPTH = 16
COMMAND_LINE = "command line"    # the source of a preset named on the command line


def presets_dir() -> Path:
    """The presets folder; PresetError when ``$CROWNDEMO_PRESETS`` names no folder."""
    env = os.environ.get("CROWNDEMO_PRESETS")
    if env:
        folder = Path(env).expanduser()
        if not folder.is_dir():
            why = "not a folder" if folder.exists() else "no such folder"
            raise PresetError("$CROWNDEMO_PRESETS", None, why=f"{why}: {env}",
                              allowed="an existing folder of preset .yaml files, or unset "
                                      "for presets/ next to the crowndemo package")
        return folder
    import crowndemo
    return Path(crowndemo.__file__).resolve().parent.parent / "presets"


def preset_names(folder: Optional[Path] = None) -> List[str]:
    folder = folder or presets_dir()
    if not folder.is_dir():
        return []
    return sorted({p.stem for p in folder.iterdir()
                   if p.suffix in SUFFIXES and p.is_file() and not p.stem.startswith("_")})


def display(path: Path) -> str:
    """How messages name a file: relative to the working directory when inside it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return str(path)
    return str(path) if rel.startswith("..") else rel


def looks_like_path(spec: str) -> bool:
    return spec.endswith(SUFFIXES) or "/" in spec or os.sep in spec


def find(spec: str, source: str = COMMAND_LINE, key: str = "preset",
         relative_to: Optional[Path] = None) -> Path:
    """The file of a preset name or path; a path is taken relative to ``relative_to``
    (the folder of the file that names it) when given."""
    if not isinstance(spec, str) or not spec.strip():
        raise PresetError(source, key, spec, "not a preset name or path",
                          "a preset name (crowndemo presets) or a path to a .yaml file")
    if looks_like_path(spec):
        path = Path(spec).expanduser()
        if relative_to is not None and not path.is_absolute():
            path = relative_to / path
        if path.is_file():
            return path.resolve()
        _not_a_folder(path, source, key, spec)
        raise PresetError(source, key, spec, f"no such file ({display(path)})",
                          "an existing .yaml file, or a preset name")
    folder = presets_dir()
    for suffix in SUFFIXES:
        path = folder / f"{spec}{suffix}"
        if path.is_file():
            return path.resolve()
    if Path(spec).is_file():          # a file without the .yaml suffix, in the working folder
        return Path(spec).resolve()
    if relative_to is None:
        _not_a_folder(Path(spec), source, key, spec)
    names = preset_names(folder)
    raise PresetError(source, key, spec,
                      f"no such preset in {display(folder)}{did_you_mean(spec, names)}",
                      (", ".join(names) or "(none)") + ", or a path to a .yaml file")


def _not_a_folder(path: Path, source: str, key: str, spec: str) -> None:
    """PresetError when ``path`` is a folder: named by itself on the command line, else by
    the file (``extends``) that names it."""
    if not path.is_dir():
        return
    allowed = "a preset .yaml file, or a preset name (crowndemo presets)"
    if source == COMMAND_LINE:
        raise PresetError(display(path), None, why="a folder, not a preset file",
                          allowed=allowed)
    raise PresetError(source, key, spec, f"a folder, not a preset file ({display(path)})",
                      allowed)


def _present(data: dict, path: Tuple[str, ...]) -> bool:
    for k in path:
        if not isinstance(data, dict) or k not in data:
            return False
        data = data[k]
    return True


@dataclass
class Document:
    """A preset after ``extends`` and merging: the data, where each value came from, and the
    order of the sources (a later source is more specific: parents < child < --set)."""
    name: str
    path: Path
    label: str
    data: dict
    origin: Origin
    chain: List[str] = field(default_factory=list)     # source labels, base first
    ranks: Dict[str, int] = field(default_factory=dict)

    @property
    def files(self) -> List[str]:
        """The chain of preset files, base first, without the ``--set`` layer."""
        return [label for label in self.chain if label != SET_SOURCE]

    def source_of(self, key_path: Iterable[str]) -> str:
        """The source that wrote a key (or the nearest enclosing one), else this file."""
        p = tuple(key_path)
        while p:
            if p in self.origin:
                return self.origin[p]
            p = p[:-1]
        return self.label

    def writer_of(self, key_path: Iterable[str]) -> str:
        """The source that wrote exactly this key (a null or an empty ``--set`` counts: it
        restored the default), else DEFAULT_SOURCE: the value is the schema's default."""
        return self.origin.get(tuple(key_path), DEFAULT_SOURCE)

    def missing_source(self, key_path: Iterable[str]) -> str:
        """Whom to name for a required key that has no value: the file or ``--set KEY=``
        whose null removed it (or an enclosing mapping), else this file."""
        p = tuple(key_path)
        while p and not _present(self.data, p):
            if p in self.origin:
                src = self.origin[p]
                return f"{src} {'.'.join(p)}=" if src == SET_SOURCE else src
            p = p[:-1]
        return self.label

    def rank_of(self, key_path: Iterable[str]) -> int:
        return self.ranks.get(self.origin.get(tuple(key_path), ""), -1)


def load(spec: str, source: str = COMMAND_LINE) -> Document:
    """Load a preset by name or path, with its ``extends`` chain merged."""
    path = find(spec, source)
    data, origin, chain = _load_chain(path, [])
    name = path.stem
    return Document(name, path, display(path), data, origin, chain,
                    {label: i for i, label in enumerate(chain)})


def _read(path: Path) -> dict:
    label = display(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise PresetError(label, None, why=f"cannot read the file: "
                          f"{getattr(e, 'strerror', None) or e}") from None
    raw = load_text(text, label)
    if not isinstance(raw, dict):
        raise PresetError(label, None, why="not a preset: the top level must be a mapping "
                          "(title:, scene:, quality:, ...)")
    return raw


def _load_chain(path: Path, stack: List[Path]):
    label = display(path)
    if path in stack:
        cycle = " -> ".join(display(p) for p in stack + [path])
        raise PresetError(display(stack[-1]), "extends", path.stem, f"extends cycle: {cycle}",
                          "a chain of presets without cycles")
    if len(stack) >= MAX_DEPTH:
        raise PresetError(label, "extends", path.stem, f"more than {MAX_DEPTH} levels of extends",
                          f"at most {MAX_DEPTH}")
    raw = _read(path)
    parent = raw.pop("extends", None)
    if parent is not None:
        if not isinstance(parent, str):
            raise PresetError(label, "extends", parent, "not a preset name or path",
                              "one preset name (crowndemo presets) or a path relative to "
                              "this file")
        base_path = find(parent, label, "extends", relative_to=path.parent)
        base, base_origin, chain = _load_chain(base_path, stack + [path])
    else:
        base, base_origin, chain = {}, {}, []
    data, origin = deep_merge(base, base_origin, raw, origin_of(raw, label))
    return data, origin, chain + [label]


__all__ = ["Document", "load", "find", "presets_dir", "preset_names", "display"]
