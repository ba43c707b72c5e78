"""Japanese text on title cards and captions (--lang ja, issue 25): with a CJK font the kanji are
drawn as themselves, not as missing-glyph boxes; without one the text falls back to English with
one warning. No Taichi kernel runs here."""
import os
import shutil

import numpy as np
import pytest

from crowndemo import config
from crowndemo.render import captions
from crowndemo.render.captions import (CJK_HINT, CaptionInfo, cjk_font_path, draw_caption,
                                       draws_japanese, effective_lang, title_card)

SIZE = (640, 360)
DEJAVU = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"   # Latin only: no kanji
FONT = cjk_font_path()        # this machine's Japanese font, or None
NO_FONT = ("no CJK font installed: 'make setup' (as root) installs Debian's "
           "fonts-ipafont-gothic; or apt-get install fonts-ipafont-gothic / fonts-noto-cjk")


@pytest.fixture
def fresh_lookup(monkeypatch):
    """The font lookup and its one-time warning as in a new process."""
    monkeypatch.delenv("CROWNDEMO_FONT", raising=False)
    monkeypatch.setattr(captions, "_warned", False)
    captions._find_cjk.cache_clear()
    yield
    captions._find_cjk.cache_clear()


@pytest.fixture
def no_fonts(fresh_lookup, monkeypatch, tmp_path):
    """A machine without a Japanese font: none in the Debian places the lookup knows (an
    empty folder instead), and fontconfig (the real fc-list) given a configuration whose only
    font folder is empty; returns that folder."""
    fc_dir, globbed = tmp_path / "fontconfig-fonts", tmp_path / "fonts"
    fc_dir.mkdir()
    globbed.mkdir()
    conf = tmp_path / "fonts.conf"
    conf.write_text(f"<?xml version='1.0'?><fontconfig><dir>{fc_dir}</dir>"
                    f"<cachedir>{tmp_path / 'cache'}</cachedir></fontconfig>")
    monkeypatch.setenv("FONTCONFIG_FILE", str(conf))
    monkeypatch.setattr(captions, "CJK_FONTS", ())
    monkeypatch.setattr(captions, "CJK_GLOBS", (str(globbed / "**" / "*.tt[cf]"),))
    return fc_dir


def ink(img: np.ndarray) -> np.ndarray:
    """Pixels that are not the card's background."""
    return np.any(img != np.array(captions.CARD_BACKGROUND, np.uint8), axis=2)


@pytest.mark.skipif(FONT is None, reason=NO_FONT)
def test_title_card_draws_the_kanji(fresh_lookup, capsys):
    """Two different kanji give two different cards (a font without them draws the same box
    for both); the same kanji twice gives the same card, so the difference is the glyph."""
    assert effective_lang("ja") == "ja"
    assert capsys.readouterr().err == ""                  # no fallback warning
    a, b = captions.KANJI_PAIR
    card = {k: title_card(SIZE, {"en": "Speed", "ja": k}, None, lang="ja") for k in (a, b)}
    assert np.array_equal(card[a], title_card(SIZE, {"en": "Speed", "ja": a}, None, lang="ja"))
    for k in (a, b):
        assert ink(card[k]).sum() > 50                     # something is drawn
    assert not np.array_equal(card[a], card[b])
    # a shipped preset's Japanese title and description, not its English ones
    r = config.load("2m-drop", "draft")
    ja = title_card(SIZE, r.title, r.description, lang="ja")
    en = title_card(SIZE, r.title, r.description, lang="en")
    assert ink(ja).sum() > 200 and not np.array_equal(ja, en)


@pytest.mark.skipif(FONT is None, reason=NO_FONT)
def test_caption_title_in_japanese(fresh_lookup):
    """The frame caption's Japanese title is drawn glyph by glyph (two kanji, two captions)."""
    blank = np.full((SIZE[1], SIZE[0], 3), 30, np.uint8)
    a, b = captions.KANJI_PAIR
    got = {k: draw_caption(blank, CaptionInfo({"en": "x", "ja": k}, 6.26, 9.81), 1e-3, "ja")
           for k in (a, b)}
    diff = np.argwhere(np.any(got[a] != got[b], axis=2))
    assert len(diff) > 20 and diff[:, 0].max() < SIZE[1] // 6    # in the title, at the top


def test_the_shipped_lookup_finds_debian_fonts_by_path():
    """The places the lookup knows include where Debian's two Japanese font packages put
    their files (dpkg -L fonts-ipafont-gothic, fonts-noto-cjk on Debian 12)."""
    assert "/usr/share/fonts/opentype/ipafont-gothic/ipagp.ttf" in captions.CJK_FONTS
    assert "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc" in captions.CJK_FONTS


def test_a_latin_font_is_not_taken_for_japanese():
    """DejaVu Sans has no kanji: both come out as the same missing-glyph box."""
    if not os.path.isfile(DEJAVU):
        pytest.skip(f"{DEJAVU} not installed (Debian's fonts-dejavu-core)")
    assert not draws_japanese(DEJAVU)


def test_japanese_falls_back_to_english_with_one_warning(no_fonts, capsys, monkeypatch):
    assert cjk_font_path() is None
    assert effective_lang("ja") == "en" and effective_lang("ja") == "en"
    err = capsys.readouterr().err
    assert err.count(CJK_HINT) == 1 and "fonts-ipafont-gothic" in err
    title = {"en": "Two metres", "ja": "二メートル"}
    desc = {"en": "a 10 mm drop", "ja": "直径10 mmの水滴"}
    assert np.array_equal(title_card(SIZE, title, desc, lang="ja"),
                          title_card(SIZE, title, desc, lang="en"))
    assert effective_lang("en") == "en"
    with pytest.raises(ValueError):
        effective_lang("fr")
    # a Latin font named by $CROWNDEMO_FONT is not taken for Japanese either
    if os.path.isfile(DEJAVU):
        monkeypatch.setenv("CROWNDEMO_FONT", DEJAVU)
        assert cjk_font_path() is None


@pytest.mark.skipif(FONT is None, reason=NO_FONT)
def test_font_named_by_env_or_listed_by_fontconfig_is_found(no_fonts, monkeypatch):
    """With the Debian places empty: the font $CROWNDEMO_FONT names; without it, one that
    fontconfig lists for Japanese (the real fc-list, given a folder holding a copy)."""
    assert cjk_font_path() is None
    monkeypatch.setenv("CROWNDEMO_FONT", FONT)
    assert cjk_font_path() == FONT
    monkeypatch.delenv("CROWNDEMO_FONT")
    if shutil.which("fc-list") is None:
        pytest.skip("no fontconfig (fc-list) here")
    copy = no_fonts / os.path.basename(FONT)
    shutil.copyfile(FONT, copy)
    captions._find_cjk.cache_clear()
    assert cjk_font_path() == str(copy)
