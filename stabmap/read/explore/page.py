"""A page: a bokeh layout written as one self-contained HTML file (BokehJS inlined: no server, no internet), shown
inline in Jupyter, and what its making left out (``notes``)."""

from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path

from ...errors import StabmapError, param
from ...store.files import check_writable

BASE_BYTES = 1_700_000  # BokehJS inlined (bokeh 3.x: about 1.7 MB), the layout and its texts: every page's floor
MAX_MB = 20.0  # the default bound of a page's size


@dataclass
class Page:
    """An interactive page: the bokeh ``layout``, its ``title``, the ``notes`` on what was left out, and the bytes
    its frames' data take (``data_bytes``, before base64)."""

    layout: object
    title: str
    notes: tuple[str, ...] = ()
    data_bytes: int = 0

    def html(self) -> str:
        """The page as one HTML document, scripts inlined."""
        from bokeh.embed import file_html
        from bokeh.resources import INLINE

        return file_html(self.layout, resources=INLINE, title=self.title)

    def save(self, path: str | Path) -> Path:
        """Write the page atomically (a temporary file renamed into place); returns the path."""
        path = check_page_path(path)
        tmp = path.with_name(f".{path.name}.tmp")
        try:
            tmp.write_text(self.html(), encoding="utf-8")
            tmp.replace(path)
        finally:
            tmp.unlink(missing_ok=True)
        return path

    def _repr_html_(self) -> str:
        # An iframe of the whole page: it runs its own BokehJS, so nothing has to be loaded into the notebook first.
        return (f'<iframe srcdoc="{html.escape(self.html(), quote=True)}" style="width: 100%; height: 900px; border: none" '
                f'title="{html.escape(self.title, quote=True)}"></iframe>')


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
