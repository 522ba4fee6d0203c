"""Drive stabmap's self-contained bokeh pages in headless Chromium, for the browser tests (a library, not a test module).

The pages follow a contract: a ``figure(name="map")`` with a HoverTool, a ``Slider(name="slider-<dim>")`` per further
axis (its value a position index), a ``Div(name="readout")`` the hover callback writes and a ``Div(name="title")``
the sliders update.  :class:`Page` reads and moves those by name, with real mouse and keyboard events, so a test sees
what a reader of the page sees.

Use::

    with browser() as new_page:          # one Chromium for a test module: it takes about a second to start
        page = new_page().open(html_path)
        page.hover("map", 1.5, 31.6)             # data coordinates; log axes too
        page.wait_text("readout", "label=r1c1")  # the Div re-renders after the hover callback, not at once
        page.move_slider("slider-K_1", 1)        # waits for the model's value

The JS below reaches into BokehJS 3.9's view tree (``Bokeh.index``), which is not a public API: if a bokeh upgrade
breaks a test here, look first at :data:`JS_HELPERS`.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

# Debian's paths first; elsewhere (another distribution, a CI image) whatever of these names is on PATH.
CHROMIUM = ("/usr/bin/chromium", "chromium", "chromium-browser")
CHROMEDRIVER = ("/usr/bin/chromedriver", "chromedriver")
INSTALL_HINT = (
    "the browser tests need Chromium, its driver and selenium; how to install: apt-get install chromium chromium-driver "
    "(Debian/Ubuntu), and pip install selenium.  Set STABMAP_REQUIRE_BROWSER=1 to make their absence a failure (CI does)."
)
# Debian's chromium starts headless with these; the network switches keep it from calling home (there may be no network).
CHROMIUM_ARGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
)

# Functions every script below can call, prepended to it (execute_script runs each script in a fresh function scope).
#
# - view(name): the BokehJS view of the document's model so named.  Bokeh.index is the ViewManager of the embedded
#   roots; find_one walks the whole view tree (roots and their children) for the view of that model.
# - shown(el): an element's rendered text.  Bokeh 3 renders each UI element into its own shadow root, so the host
#   element's innerText is empty; a Div's text lives in view.markup_el, a tooltip's in its shadow root (next to the
#   <style> elements, whose text is not shown and is skipped).
# - deep(root): every element under root, descending into open shadow roots, which querySelectorAll does not.
# - plain(v): v made JSON-like for webdriver: typed arrays to arrays, Maps to objects, models to their name/id/type.
JS_HELPERS = r"""
const doc = Bokeh.documents[0];
function model(name) {
  const m = doc.get_model_by_name(name);
  if (m == null) throw new Error(`no model named ${name}`);
  return m;
}
function view(name) {
  const v = Bokeh.index.find_one(model(name));
  if (v == null) throw new Error(`the model named ${name} has no view`);
  return v;
}
function* deep(root) {
  for (const el of root.querySelectorAll("*")) {
    yield el;
    if (el.shadowRoot != null) yield* deep(el.shadowRoot);
  }
}
function shown(node) {
  if (node instanceof HTMLElement) return node.innerText;
  // a ShadowRoot has no innerText: join its shown children's
  return Array.from(node.children).filter((c) => !["STYLE", "LINK", "SCRIPT"].includes(c.tagName)).map(shown).join("\n");
}
function plain(v, depth = 0) {
  if (v == null || typeof v != "object") return v;
  if (ArrayBuffer.isView(v)) return Array.from(v);
  if (depth > 8) return String(v);
  if (Array.isArray(v)) return v.map((x) => plain(x, depth + 1));
  if (v instanceof Map) return Object.fromEntries(Array.from(v, ([k, x]) => [String(k), plain(x, depth + 1)]));
  if (typeof v.id == "string" && typeof v.type == "string" && "properties" in v) return {id: v.id, type: v.type, name: v.name};
  return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, plain(x, depth + 1)]));
}
"""

_READY_JS = """
if (!(window.Bokeh && Bokeh.documents && Bokeh.documents.length && Bokeh.index)) return false;
const doc = Bokeh.documents[0];
for (const name of arguments[0]) {
  const m = doc.get_model_by_name(name);
  if (m == null || Bokeh.index.find_one(m) == null) return false;
}
return doc.is_idle;
"""


def chromium_or_skip() -> tuple[str, str]:
    """The paths of Chromium and its driver, or skip the calling test when either (or selenium) is missing.

    Returns
    -------
    tuple of str
        ``(chromium, chromedriver)``.

    Raises
    ------
    pytest.skip.Exception
        Without them, unless the environment variable ``STABMAP_REQUIRE_BROWSER`` is ``1``: then ``pytest.fail``, so a
        CI machine that lost its browser fails loudly instead of passing with the browser tests skipped.
    """
    found = {names[0]: next(filter(None, map(shutil.which, names)), None) for names in (CHROMIUM, CHROMEDRIVER)}
    missing = [name for name, path in found.items() if path is None]
    try:
        import selenium  # noqa: F401
    except ImportError:
        missing.append("the python package selenium")
    if missing:
        message = f"missing {', '.join(missing)}: {INSTALL_HINT}"
        if os.environ.get("STABMAP_REQUIRE_BROWSER") == "1":
            pytest.fail(message, pytrace=False)
        pytest.skip(message)
    return found[CHROMIUM[0]], found[CHROMEDRIVER[0]]


@contextlib.contextmanager
def browser(width: int = 1400, height: int = 1000) -> Iterator[Callable[[], Page]]:
    """Start one headless Chromium; yield a factory of :class:`Page` on it; quit it (and remove its profile) at the end.

    Skips (or fails, see :func:`chromium_or_skip`) when Chromium is not installed.  A module wraps it in a fixture::

        @pytest.fixture(scope="module")
        def new_page():
            with browser() as factory:
                yield factory

    Parameters
    ----------
    width, height : int
        The page's viewport in CSS pixels (one device pixel each); screenshots have this size.

    Yields
    ------
    callable
        ``new_page()``, a :class:`Page` on the one browser tab (pages share it: open one page at a time).
    """
    chromium, chromedriver = chromium_or_skip()
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    with tempfile.TemporaryDirectory(prefix="stabmap-chromium-") as profile:
        options = Options()
        options.binary_location = chromium
        for arg in CHROMIUM_ARGS:
            options.add_argument(arg)
        options.add_argument(f"--user-data-dir={profile}")
        options.add_argument(f"--window-size={width},{height}")
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})  # for Page.errors
        # An explicit driver path keeps selenium from running selenium-manager, which would try to download one.
        driver = webdriver.Chrome(options=options, service=Service(executable_path=chromedriver))
        try:
            # The window's size includes the browser's own bars; fix the page's viewport instead, at one device pixel
            # per CSS pixel, so that screenshots and pixel positions are the same on every machine.
            driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
            yield lambda: Page(driver)
        finally:
            driver.quit()


class Page:
    """One bokeh page in the browser, read and moved through the names of its models.

    Parameters
    ----------
    driver : selenium.webdriver.Remote
        The browser, e.g. from :func:`browser`.
    timeout : float
        Seconds to wait for the page to render and for a slider's value to change before raising ``TimeoutError``.
    """

    def __init__(self, driver, timeout: float = 20.0):
        self.driver = driver
        self.timeout = timeout

    def js(self, body: str, *args):
        """Run ``body`` (JS with a ``return``) after :data:`JS_HELPERS`, with ``arguments[i]`` the ``args``."""
        return self.driver.execute_script(JS_HELPERS + body, *args)

    def wait(self, what: str, read: Callable[[], object], accept: Callable[[object], bool] = bool):
        """Call ``read`` until ``accept`` takes its value, and return that value.

        Raises
        ------
        TimeoutError
            After :attr:`timeout` seconds, naming ``what`` and the last value read.
        """
        end = time.monotonic() + self.timeout
        while True:
            value = read()
            if accept(value):
                return value
            if time.monotonic() > end:
                raise TimeoutError(f"waited {self.timeout} s for {what}; the last value was {value!r}")
            time.sleep(0.02)

    def open(self, path: str | os.PathLike, names: tuple[str, ...] = ("map",)) -> Page:
        """Load the HTML file ``path`` and wait until Bokeh has rendered it.

        Rendered: the document exists, the models named ``names`` have views, and the document is idle (every view
        has painted once).

        Returns
        -------
        Page
            ``self``, for ``new_page().open(path)``.
        """
        self.driver.get(Path(path).resolve().as_uri())
        try:
            self.wait(f"bokeh to render {path} with views of {names}", lambda: self.driver.execute_script(_READY_JS, list(names)))
        except TimeoutError as error:
            raise TimeoutError(f"{error}; the page's errors: {self.errors()}") from None
        return self

    def errors(self) -> list[str]:
        """The messages the page logged as errors (uncaught exceptions, ``console.error``) since the last call."""
        return [entry["message"] for entry in self.driver.get_log("browser") if entry["level"] == "SEVERE"]

    def model(self, name: str) -> ModelRef:
        """The model named ``name``; its properties read through JS: ``page.model("slider-K_1").value``."""
        return ModelRef(self, name)

    def text(self, name: str) -> str:
        """The text the Div (or other markup widget) named ``name`` shows: rendered, so without HTML tags."""
        return self.js("const v = view(arguments[0]); return shown(v.markup_el ?? v.shadow_el ?? v.el);", name).strip()

    def wait_text(self, name: str, contains: str) -> str:
        """Wait until the text :meth:`text` reads from ``name`` contains ``contains``, and return that text.

        Bokeh re-renders a Div after its model changed, not at once: read it after a hover or a slider through this.
        """
        return self.wait(f"the text of {name} to contain {contains!r}", lambda: self.text(name), lambda text: contains in text)

    def wait_tooltip(self, contains: str) -> str:
        """Wait until a shown hover tooltip's text (:meth:`tooltip_text`) contains ``contains``, and return that text."""
        return self.wait(f"a tooltip with {contains!r}", self.tooltip_text, lambda text: contains in text)

    def point(self, plot_name: str, x: float, y: float) -> tuple[float, float]:
        """The viewport (CSS pixel) position of data coordinates ``(x, y)`` of the figure named ``plot_name``.

        The frame's scales map data to canvas pixels (log axes included); the canvas's bounding rectangle places the
        canvas in the viewport.  The page is scrolled first so that the figure is in view.
        """
        return tuple(
            self.js(
                """
                const v = view(arguments[0]);
                v.el.scrollIntoView({block: "nearest", inline: "nearest"});
                const rect = v.canvas.events_el.getBoundingClientRect();
                return [rect.left + v.frame.x_scale.compute(arguments[1]), rect.top + v.frame.y_scale.compute(arguments[2])];
                """,
                plot_name,
                x,
                y,
            )
        )

    def hover(self, plot_name: str, x: float, y: float) -> None:
        """Move the real mouse to data coordinates ``(x, y)`` of the figure named ``plot_name`` (see :meth:`point`).

        Raises ``ValueError`` when the point is outside the figure's frame, where a hover would show nothing.
        """
        from selenium.webdriver.common.action_chains import ActionChains

        inside = self.js(
            """
            const v = view(arguments[0]);
            const [sx, sy] = [v.frame.x_scale.compute(arguments[1]), v.frame.y_scale.compute(arguments[2])];
            return v.frame.bbox.contains(sx, sy);
            """,
            plot_name,
            x,
            y,
        )
        if not inside:
            raise ValueError(f"({x}, {y}) is outside the frame of {plot_name}")
        px, py = (round(c) for c in self.point(plot_name, x, y))  # webdriver moves by whole pixels
        # A pointer that does not move fires no mousemove, and so no hover: arrive from the next pixel, so that hovering
        # the same point again (after a slider changed the data under it) updates the tooltip and the readout.
        actions = ActionChains(self.driver, duration=0)  # one mousemove per move, not a 250 ms glide
        actions.w3c_actions.pointer_action.move_to_location(px + 1, py)
        actions.w3c_actions.pointer_action.move_to_location(px, py)
        actions.perform()

    def tooltip_text(self) -> str:
        """The text of the hover tooltip on show ("" when none is), wherever in the shadow roots it lives."""
        return self.js(
            """
            const texts = [];
            for (const el of deep(document)) {
              if (!el.classList.contains("bk-Tooltip") || el.shadowRoot == null) continue;
              const rect = el.getBoundingClientRect();
              if (rect.width > 0 && rect.height > 0 && getComputedStyle(el).visibility != "hidden") texts.push(shown(el.shadowRoot));
            }
            return texts.join("\\n");
            """
        ).strip()

    def move_slider(self, name: str, steps: int) -> int:
        """Move the horizontal slider named ``name`` by ``steps`` steps with the keyboard; wait for the model's new value.

        The slider's handle is clicked (which focuses it without moving it) and then the arrow keys pressed, as a
        reader would.  The value stops at the slider's ends.

        Returns
        -------
        int or float
            The slider's new value (the model's, once it has reached it).
        """
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.keys import Keys

        handle, start, low, high, step = self.js(
            """
            const v = view(arguments[0]);
            const handle = v.shadow_el.querySelector(".noUi-handle");
            if (handle == null) throw new Error(`the slider ${arguments[0]} has no handle`);
            handle.scrollIntoView({block: "nearest", inline: "nearest"});
            return [handle, v.model.value, v.model.start, v.model.end, v.model.step];
            """,
            name,
        )
        target = min(max(start + steps * step, low), high)
        key = Keys.ARROW_RIGHT if steps > 0 else Keys.ARROW_LEFT
        actions = ActionChains(self.driver, duration=0).click(handle)
        for _ in range(abs(steps)):
            actions.send_keys(key)
        actions.perform()
        return self.wait(f"{name} to move from {start} to {target}", lambda: self.model(name).value, lambda value: value == target)

    def screenshot(self, path: str | os.PathLike) -> Path:
        """Save the browser window as a PNG at ``path`` (the window's size in pixels) and return the path."""
        path = Path(path)
        if not self.driver.save_screenshot(str(path)):
            raise OSError(f"the browser could not save a screenshot to {path}")
        return path


class ModelRef:
    """A model of the page, by name; reading an attribute reads that property in the browser (JSON-like: typed arrays
    come back as lists, models as ``{"id", "type", "name"}``)."""

    def __init__(self, page: Page, name: str):
        self._page = page
        self._name = name

    def __getattr__(self, prop: str):
        if prop.startswith("_"):
            raise AttributeError(prop)
        return self._page.js(
            """
            const m = model(arguments[0]);
            if (!(arguments[1] in m.properties)) throw new Error(`${m.type} ${arguments[0]} has no property ${arguments[1]}`);
            return plain(m[arguments[1]]);
            """,
            self._name,
            prop,
        )

    def __repr__(self) -> str:
        return f"ModelRef({self._name!r})"
