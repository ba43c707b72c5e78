"""Text on images, with Pillow: the caption of each frame (preset title, simulated time, drop
speed and fall height, and the key of the colour scale) and the title cards of the booth loop,
in English or Japanese.

Japanese needs a CJK font: $CROWNDEMO_FONT, else one in the usual Debian places
(fonts-ipafont-gothic, which `make` installs, fonts-noto-cjk, ...), else any font fontconfig
lists for Japanese; a font is taken only if it draws Japanese (two different kanji must not come
out as the same bitmap, a missing-glyph box). Without one, Japanese text falls back to English
with a one-time warning that says how to install a font.
"""
from __future__ import annotations

import functools
import glob
import os
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from typing import TYPE_CHECKING, Dict, List, Optional, Tuple, Union

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .colours import ColourScale, colour_map

if TYPE_CHECKING:
    from ..config.resolve import Resolved

LANGS = ("en", "ja")
LATIN_FONTS = ("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
               "/usr/share/fonts/TTF/DejaVuSans.ttf")
CJK_FONTS = ("/usr/share/fonts/opentype/ipafont-gothic/ipagp.ttf",
             "/usr/share/fonts/opentype/ipafont-gothic/ipag.ttf",
             "/usr/share/fonts/truetype/fonts-japanese-gothic.ttf",
             "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc",
             "/usr/share/fonts/opentype/noto/NotoSansCJKjp-Regular.otf",
             "/usr/share/fonts/truetype/vlgothic/VL-PGothic-Regular.ttf",
             "/usr/share/fonts/truetype/droid/DroidSansFallbackFull.ttf")
CJK_GLOBS = ("/usr/share/fonts/**/*ipag*.ttf", "/usr/share/fonts/**/*CJK*-Regular.tt[cf]",
             "/usr/share/fonts/**/*CJK*.tt[cf]", "/usr/share/fonts/**/*CJK*.otf")
FC_LIST = "fc-list"        # fontconfig's lister: the fonts it knows for a language
CJK_HINT = ("no Japanese (CJK) font found, so Japanese text is shown in English; install one "
            "with 'apt-get install fonts-ipafont-gothic' (3.5 MB download, 12.5 MB installed; "
            "'make setup' does this as root) or point $CROWNDEMO_FONT at a .ttf/.otf/.ttc file "
            "with Japanese glyphs")
KANJI_PAIR = ("速", "圧")    # two different kanji of the captions: a font without them draws both
                             # as the same missing-glyph box (or nothing)
TEXT = (240, 240, 240)
DIM_TEXT = (190, 196, 205)
BAND = (0, 0, 0, 150)
CARD_BACKGROUND = (14, 16, 22)
MARKER = (230, 80, 60)
# the colour key of each scaled colour field: its name, and the factor and unit its ends are
# shown in (milk has no scale to show)
KEYS = {"speed": ({"en": "speed", "ja": "速さ"}, 1.0, "m/s"),
        "height": ({"en": "height above the floor", "ja": "床からの高さ"}, 1e3, "mm"),
        "pressure": ({"en": "pressure", "ja": "圧力"}, 1e-3, "kPa")}
_warned = False


def draws_japanese(path: str) -> bool:
    """Whether the font file draws Japanese: the two kanji of KANJI_PAIR come out as different,
    non-empty bitmaps (a font without them gives the same missing-glyph box, or nothing)."""
    try:
        f = ImageFont.truetype(path, 32)
    except OSError:                       # not a font file Pillow can read
        return False
    a, b = (np.asarray(f.getmask(ch), dtype=np.uint8) for ch in KANJI_PAIR)
    if not a.any() or not b.any():
        return False
    return a.shape != b.shape or bool((a != b).any())


def _fontconfig_japanese(fc_list: str) -> List[str]:
    """The font files fontconfig lists as covering Japanese (none without fontconfig)."""
    try:
        out = subprocess.run([fc_list, ":lang=ja", "file"], capture_output=True, text=True,
                             timeout=20).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return sorted({line.split(":")[0].strip() for line in out.splitlines() if line.strip()})


@functools.lru_cache(maxsize=8)
def _find_cjk(env: Optional[str], paths: Tuple[str, ...], patterns: Tuple[str, ...],
              fc_list: str) -> Optional[str]:
    def candidates():
        if env:
            yield env
        yield from paths
        for pattern in patterns:
            yield from sorted(glob.glob(pattern, recursive=True))
        yield from _fontconfig_japanese(fc_list)
    for path in candidates():
        if os.path.isfile(path) and draws_japanese(path):
            return path
    return None


def cjk_font_path() -> Optional[str]:
    """The font file for Japanese text, or None: $CROWNDEMO_FONT, the usual Debian places
    (CJK_FONTS, CJK_GLOBS), then fontconfig's Japanese fonts; the first that draws Japanese
    (looked up once per process and value of $CROWNDEMO_FONT)."""
    return _find_cjk(os.environ.get("CROWNDEMO_FONT") or None, tuple(CJK_FONTS),
                     tuple(CJK_GLOBS), FC_LIST)


def effective_lang(lang: str) -> str:
    """``lang``, or 'en' (with a one-time warning on stderr) when Japanese has no font."""
    global _warned
    if lang not in LANGS:
        raise ValueError(f"language {lang!r} is not one of {', '.join(LANGS)}")
    if lang == "ja" and cjk_font_path() is None:
        if not _warned:
            print(f"crowndemo: warning: {CJK_HINT}", file=sys.stderr)
            _warned = True
        return "en"
    return lang


def font(lang: str, size: int) -> ImageFont.FreeTypeFont:
    """A font for ``lang`` (a CJK font covers Latin too) at ``size`` pixels."""
    candidates = ([cjk_font_path()] if lang == "ja" else []) + list(LATIN_FONTS)
    for path in candidates:
        if path and os.path.isfile(path):
            return ImageFont.truetype(path, size)
    return ImageFont.load_default(size=size)       # Pillow's own scalable font


def text_in(texts: Union[str, Dict[str, str], None], lang: str) -> str:
    """A text given as one string or {en: ..., ja: ...}, in ``lang`` (else English)."""
    if isinstance(texts, dict):
        return texts.get(lang) or texts.get("en") or next(iter(texts.values()), "")
    return str(texts or "")


@dataclass(frozen=True)
class CaptionInfo:
    """What a frame's caption says about the run."""
    title: Dict[str, str]
    speed: float                    # m/s
    gravity: float                  # m/s^2

    @classmethod
    def from_resolved(cls, resolved: Resolved) -> "CaptionInfo":
        return cls(dict(resolved.title) if isinstance(resolved.title, dict)
                   else {"en": str(resolved.title)}, resolved.speed,
                   resolved.scene["gravity"])

    @property
    def height(self) -> Optional[float]:
        """The fall height that gives the impact speed without drag: U^2 / (2 g)."""
        return self.speed ** 2 / (2 * self.gravity) if self.gravity > 0 else None


def _length(metres: float) -> str:
    return f"{metres:.2f} m" if metres >= 1 else f"{metres * 100:.3g} cm"


def caption_lines(info: CaptionInfo, time: float, lang: str) -> List[str]:
    """The caption's two lines: the title, then time, speed and height."""
    t = f"t = {time * 1e3:.3f} ms"
    u = f"U = {info.speed:.3g} m/s"
    h = info.height
    if lang == "ja":
        parts = [t, f"衝突速度 {u}"] + ([f"落下高さ U²/2g = {_length(h)}"] if h else [])
        return [text_in(info.title, "ja"), "　".join(parts)]
    parts = [t, f"drop speed {u}"] + ([f"fall height U²/2g = {_length(h)}"] if h else [])
    return [text_in(info.title, "en"), "   ".join(parts)]


def key_labels(scale: ColourScale, lang: str) -> Optional[Tuple[str, str, str]]:
    """(name, low end, high end) of the colour key for ``scale``, or None (milk: no scale)."""
    if scale.mode not in KEYS:
        return None
    names, factor, unit = KEYS[scale.mode]
    return names[lang], f"{scale.lo * factor:.3g}", f"{scale.hi * factor:.3g} {unit}"


def key_text(scale: ColourScale, lang: str) -> Optional[str]:
    """The colour key in one line of text (live mode's panel): 'colours: speed 0 (blue) to
    6.26 m/s (red)'; None for milk."""
    labels = key_labels(scale, lang)
    if labels is None:
        return None
    name, lo, hi = labels
    if lang == "ja":
        return f"色: {name} {lo}（青）〜 {hi}（赤）"
    return f"colours: {name} {lo} (blue) to {hi} (red)"


def _colour_key(d: ImageDraw.ImageDraw, overlay: Image.Image, scale: ColourScale, lang: str,
                f, pad: int, band_h: int) -> None:
    """The colour map as a bar at the right of the caption band, on the level of its second
    line, between its low and high ends, with its name above it."""
    labels = key_labels(scale, lang)
    if labels is None:
        return
    name, lo, hi = labels
    width = overlay.width // 6
    bar_h = max(4, f.size * 2 // 3)
    middle = band_h - pad - f.size // 2              # the second line's middle
    right = overlay.width - 2 * pad - int(d.textlength(hi, font=f)) - pad
    left, top = right - width, middle - bar_h // 2
    ramp = (255 * colour_map(np.linspace(0.0, 1.0, width))).astype(np.uint8)
    strip = np.repeat(ramp[None], bar_h, axis=0)
    overlay.paste(Image.fromarray(np.dstack([strip, np.full(strip.shape[:2], 255, np.uint8)]),
                                  "RGBA"), (left, top))
    d.text((left - pad, middle), lo, font=f, fill=DIM_TEXT, anchor="rm")
    d.text((right + pad, middle), hi, font=f, fill=DIM_TEXT, anchor="lm")
    d.text(((left + right) // 2, top - pad // 2), name, font=f, fill=TEXT, anchor="mb")


def draw_caption(image: np.ndarray, info: CaptionInfo, time: float, lang: str = "en",
                 marker: Optional[str] = None,
                 scale: Optional[ColourScale] = None) -> np.ndarray:
    """The image (h, w, 3 uint8) with a caption band across its top (with the key of
    ``scale``, the particles' colours, at its right); a new array."""
    lang = effective_lang(lang)
    img = Image.fromarray(image).convert("RGBA")
    h = img.height
    big, small = font(lang, max(10, h // 24)), font(lang, max(8, h // 36))
    title, line = caption_lines(info, time, lang)
    pad = max(4, h // 60)
    band_h = pad * 3 + big.size + small.size
    overlay = Image.new("RGBA", img.size, (0, 0, 0, 0))
    d = ImageDraw.Draw(overlay)
    d.rectangle([0, 0, img.width, band_h], fill=BAND)
    d.text((pad * 2, pad), title, font=big, fill=TEXT)
    d.text((pad * 2, pad * 2 + big.size), line, font=small, fill=DIM_TEXT)
    if scale is not None:
        _colour_key(d, overlay, scale, lang, small, pad, band_h)
    if marker:
        _marker(d, img.size, marker, small, pad)
    return np.asarray(Image.alpha_composite(img, overlay).convert("RGB"))


def _marker(d: ImageDraw.ImageDraw, size: Tuple[int, int], text: str, f, pad: int) -> None:
    """A red label in the bottom-right corner (an incomplete recording)."""
    x0, y0, x1, y1 = d.textbbox((0, 0), text, font=f)
    w, h = x1 - x0 + 2 * pad, y1 - y0 + 2 * pad
    box = [size[0] - w - pad, size[1] - h - pad, size[0] - pad, size[1] - pad]
    d.rectangle(box, fill=MARKER + (220,))
    d.text((box[0] + pad - x0, box[1] + pad - y0), text, font=f, fill=(255, 255, 255))


def mark(image: np.ndarray, text: str, lang: str = "en") -> np.ndarray:
    """The image with a red label in its bottom-right corner; a new array."""
    img = Image.fromarray(image).convert("RGBA")
    overlay = Image.new("RGBA", img.size, (0, 0, 0, 0))
    h = img.height
    _marker(ImageDraw.Draw(overlay), img.size, text, font(effective_lang(lang), max(9, h // 28)),
            max(4, h // 60))
    return np.asarray(Image.alpha_composite(img, overlay).convert("RGB"))


def title_card(size: Tuple[int, int], title: Union[str, Dict[str, str], None],
               description: Union[str, Dict[str, str], None], lang: str = "en",
               marker: Optional[str] = None) -> np.ndarray:
    """A card (h, w, 3 uint8): the title large, the description wrapped beneath it."""
    lang = effective_lang(lang)
    w, h = size
    img = Image.new("RGBA", (w, h), CARD_BACKGROUND + (255,))
    d = ImageDraw.Draw(img)
    big, small = font(lang, max(12, h // 14)), font(lang, max(9, h // 28))
    title_text, desc_text = text_in(title, lang), text_in(description, lang)
    # wrap the description to about 80 % of the width (by characters of the average width)
    avg = max(1.0, d.textlength("あ" if lang == "ja" else "n", font=small))
    lines = textwrap.wrap(desc_text, max(8, int(0.8 * w / avg))) if desc_text else []
    lines = lines[:6]
    gap = small.size // 2
    block = big.size + 2 * gap + len(lines) * (small.size + gap)
    y = (h - block) // 2
    d.text((w // 2, y), title_text, font=big, fill=TEXT, anchor="ma")
    y += big.size + 2 * gap
    for line in lines:
        d.text((w // 2, y), line, font=small, fill=DIM_TEXT, anchor="ma")
        y += small.size + gap
    if marker:
        _marker(d, (w, h), marker, small, max(4, h // 60))
    return np.asarray(img.convert("RGB"))


__all__ = ["LANGS", "CJK_HINT", "CaptionInfo", "caption_lines", "draw_caption", "title_card", "mark",
           "cjk_font_path", "draws_japanese", "effective_lang", "font", "text_in", "key_labels",
           "key_text"]
