"""Presets: YAML files that describe a drop-on-film run (crowndemo.scenes.crown) with a ladder
of qualities (draft, booth, seed).

One job per module:

- ``errors``    PresetError (file, key, value, why, allowed) and did-you-mean;
- ``yamlio``    YAML reading (``1e-3`` is a number, duplicate keys and syntax errors reported);
- ``merge``     deep merge that keeps where each value came from;
- ``loader``    the presets folder, names and paths, ``extends`` chains;
- ``overrides`` ``--set KEY.PATH=VALUE``;
- ``schema``    every key with its type, unit, range and default; ``validate``;
- ``resolve``   a quality -> ``crown(...)`` keywords + Numerics, and the checks across values;
- ``estimate``  particle counts, steps, memory and run time without running a kernel.

``load(spec, quality, sets)`` does it all: name or path -> Resolved.
"""
from __future__ import annotations

from typing import Iterable, Optional

from .errors import PresetError
from .loader import COMMAND_LINE, Document, display, find, preset_names, presets_dir
from .resolve import Resolved, resolve
from .schema import LIQUIDS, QUALITIES

DEFAULT_QUALITY = "draft"


def load_document(spec: str, sets: Optional[Iterable[str]] = None,
                  source: str = COMMAND_LINE) -> Document:
    """A preset (name or path) with its extends chain and the ``--set`` overrides merged."""
    from . import loader, overrides
    return overrides.apply(loader.load(spec, source), sets or ())


def load(spec: str, quality: str = DEFAULT_QUALITY, sets: Optional[Iterable[str]] = None,
         source: str = COMMAND_LINE) -> Resolved:
    """Load, override, validate and resolve a preset; PresetError on the first mistake."""
    return resolve(load_document(spec, sets, source), quality)


__all__ = ["PresetError", "Resolved", "Document", "load", "load_document", "resolve", "find",
           "preset_names", "presets_dir", "display", "QUALITIES", "LIQUIDS", "DEFAULT_QUALITY"]
