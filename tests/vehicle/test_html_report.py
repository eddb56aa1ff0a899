"""parksteer diagnose --html: one self-contained page that parses, holds the figures and tables, and renders."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest

from parksteer.cli import main

VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
# Attributes that make a browser fetch something (HTML and SVG).
FETCHING = {"src", "href", "xlink:href", "data", "action", "poster", "srcset", "background", "formaction"}


class _Page(HTMLParser):
    """Collects the tags, checks they nest, and every attribute that could fetch something."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.tags, self.fetches, self.errors, self.text = [], [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.fetches += [(tag, k, v) for k, v in attrs if k in FETCHING]
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):  # <path ... /> in inline SVG
        self.tags.append(tag)
        self.fetches += [(tag, k, v) for k, v in attrs if k in FETCHING]

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


@pytest.fixture(scope="module")
def report(written, tmp_path_factory):
    """A diagnosis of one cycle with rack breakaway friction hidden, written as JSON and as the HTML page."""
    paths, _ = written("html_stiction", kind="candidate", hidden="rack_stiction", strength=400.0)
    out = tmp_path_factory.mktemp("html") / "report.html"
    json_out = out.with_suffix(".json")
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["diagnose", *map(str, paths), "--json", "--html", str(out)]) == 0
    json_out.write_text(buffer.getvalue())
    return out, json.loads(buffer.getvalue())


def test_page_is_self_contained_and_parses(report):
    """The page's tags nest, it loads no script, stylesheet, frame or image from anywhere, every reference is to
    an id inside the page, and the only URLs are XML namespace names (identifiers a browser never fetches)."""
    path, _ = report
    text = path.read_text(encoding="utf-8")
    page = _Page()
    page.feed(text)
    page.close()
    assert text.startswith("<!DOCTYPE html>")
    assert page.errors == [] and page.stack == []
    assert not {"script", "link", "iframe", "img", "object", "embed"} & set(page.tags)
    assert page.fetches and all(v.startswith("#") for _, _, v in page.fetches), page.fetches[:5]
    referenced = {v[1:] for _, _, v in page.fetches} | set(re.findall(r"url\(#([^)]+)\)", text))
    ids = set(re.findall(r'\bid="([^"]+)"', text))
    assert referenced <= ids  # every reference lands inside the page
    assert len(ids) == len(re.findall(r'\bid="', text))  # no id twice (two figures' glyphs and clips kept apart)
    assert not re.search(r"url\((?!#)", text) and "@import" not in text
    for url in re.findall(r"""(?:https?|ftp|file)://[^"'\s<>)]+""", text):
        assert re.search(rf'xmlns(:\w+)?="{re.escape(url)}"', text), url


def test_page_holds_the_figures_and_the_numbers(report):
    """Three inline figures (overlay with residual and ranking; residual by phase; error ladder), the verdict, the
    residual by phase, the ladder down to the hidden effect, every calibrated parameter with its interval and every
    ranked candidate of the same diagnosis's JSON."""
    path, result = report
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    text = " ".join(page.text)
    assert page.tags.count("svg") == 3 and page.tags.count("figure") == 3
    assert f"Verdict: {result['verdict']}" in text
    assert "Residual by phase" in text and "plateau" in text
    assert "Error ladder" in text and "paper's model" in text and "+ rack_stiction" in text
    for key in result["calibrated"]:
        assert key in text
    assert text.count(" to ") >= len(result["calibrated"])
    for candidate in result["ranking"]:
        assert candidate["effect"] in text


def _chromium():
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


def test_page_renders_in_a_headless_browser(report, tmp_path):
    """Chromium, headless and offline, renders the page to a screenshot that is not blank: a good share of
    pixels are not background, in many colours (figures and tables drawn)."""
    browser = _chromium()
    if browser is None:
        pytest.skip("no chromium on this machine (apt-get install chromium) to render the page")
    path, _ = report
    shot = tmp_path / "page.png"
    run = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                          "--disable-background-networking", "--window-size=1200,2600", f"--screenshot={shot}",
                          path.as_uri()], capture_output=True, text=True, timeout=120)
    assert shot.exists(), run.stderr[-2000:]
    import matplotlib.image

    image = matplotlib.image.imread(shot)[..., :3]
    assert image.shape[0] >= 2000 and image.shape[1] >= 1000
    ink = np.any(image < 0.95, axis=-1)
    assert ink.mean() > 0.02, f"only {ink.mean():.3%} of the screenshot is drawn"
    colours = np.unique((image[ink] * 255).astype(np.uint8), axis=0)
    assert len(colours) > 20
    rows_drawn = np.flatnonzero(ink.any(axis=1))
    assert rows_drawn[-1] - rows_drawn[0] > 0.5 * image.shape[0]  # drawn down the page, not a stray header
