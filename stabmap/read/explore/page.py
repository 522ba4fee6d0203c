"""A page: a bokeh layout written as one self-contained HTML file (BokehJS inlined: no server, no internet), shown
inline in Jupyter, and what its making left out (``notes``)."""

from __future__ import annotations

import html
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import StabmapError, given, param
from ...store.files import check_writable, write_text
from .plan import PagePlan, thin

BASE_BYTES = 1_700_000  # BokehJS inlined (bokeh 3.x: about 1.7 MB), the layout and its texts: every page's floor
MAX_MB = 20.0  # the default bound of a page's size


@dataclass
class Page:
    """An interactive page: the bokeh ``layout``, its ``title`` and the ``notes`` on what was left out."""

    layout: object
    title: str
    notes: tuple[str, ...] = ()
    _html: str | None = field(default=None, repr=False)

    def html(self) -> str:
        """The page as one HTML document, scripts inlined (made once)."""
        from bokeh.embed import file_html
        from bokeh.resources import INLINE

        if self._html is None:
            self._html = file_html(self.layout, resources=INLINE, title=self.title)
        return self._html

    @property
    def size(self) -> int:
        """The page's bytes as a file (UTF-8)."""
        return len(self.html().encode())

    def save(self, path: str | Path) -> Path:
        """Write the page atomically (``store.files.write_text``); returns the path."""
        return write_text(self.html(), check_page_path(path))

    def _repr_html_(self) -> str:
        # An iframe of the whole page: it runs its own BokehJS, so nothing has to be loaded into the notebook first.
        return (f'<iframe srcdoc="{html.escape(self.html(), quote=True)}" style="width: 100%; height: 900px; border: none" '
                f'title="{html.escape(self.title, quote=True)}"></iframe>')


def fitted(full: PagePlan, sizes: dict, max_mb: float, guess: int, make: Callable[[PagePlan], Page]) -> Page:
    """The page ``make`` draws of ``full`` with as many slider settings as keep it under ``max_mb`` MB, measured on the
    page itself: first ``guess`` settings, then fewer in proportion while it is too big (evenly spaced values kept;
    the note says so, once). A page that is too big with one setting is an error."""
    why = f"the page's size bound, {given('max_mb', max_mb)}; a value left out can be chosen with {param('sel')}"
    allowed = max(1, guess)
    while True:
        plan = thin(full, sizes, allowed, why)
        page = make(plan)
        if page.size <= max_mb * 1e6:
            return page
        if len(plan.frames) == 1:
            raise StabmapError(f"one map of this file makes a page of {page.size / 1e6:.1f} MB, over {param('max_mb')} {max_mb:g}; "
                               "give a larger one")
        n = len(plan.frames)
        allowed = max(1, min(n - 1, int(n * (max_mb * 1e6 - BASE_BYTES) / max(1.0, page.size - BASE_BYTES) * 0.95)))


def check_page_path(path: str | Path) -> Path:
    """A page file that can be written: an .html name in a writable directory."""
    path = check_writable(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise StabmapError(f"page file {str(path)!r}: use an .html name")
    return path


def budget(max_mb: float) -> int:
    """Bytes of frame data a page of ``max_mb`` MB may hold (base64 makes 4 bytes of 3, BokehJS comes first)."""
    if isinstance(max_mb, bool) or not isinstance(max_mb, (int, float)) or not max_mb > 0:
        raise StabmapError(f"{param('max_mb')} must be a positive number of megabytes, got {max_mb!r}")
    room = max_mb * 1e6 - BASE_BYTES
    if room < 100_000:
        raise StabmapError(f"{param('max_mb')} {max_mb:g}: a page needs at least {(BASE_BYTES + 100_000) / 1e6:.1f} MB (BokehJS alone is "
                           f"{BASE_BYTES / 1e6:.1f} MB); give a larger one")
    return int(room * 3 / 4)
