"""Text of a page: the figures' mathtext (``$\\omega_{2}$``, ``s$^{-1}$``) as plain Unicode (ω₂, s⁻¹), which a
browser shows without a math renderer, and the lines a page shows for a grid value or a block of them."""

from __future__ import annotations

import html
import re

import numpy as np
import xarray as xr

from ...scene import units
from ..plot.labels import axis_label, symbol, units_text

GREEK = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "zeta": "ζ", "eta": "η", "theta": "θ",
    "iota": "ι", "kappa": "κ", "lambda": "λ", "mu": "μ", "nu": "ν", "xi": "ξ", "pi": "π", "rho": "ρ", "sigma": "σ",
    "tau": "τ", "phi": "φ", "chi": "χ", "psi": "ψ", "omega": "ω", "Gamma": "Γ", "Delta": "Δ", "Theta": "Θ",
    "Lambda": "Λ", "Pi": "Π", "Sigma": "Σ", "Phi": "Φ", "Psi": "Ψ", "Omega": "Ω", "times": "×", "cdot": "·",
}
_SUB = str.maketrans("0123456789+-=()aehijklmnoprstuvx", "₀₁₂₃₄₅₆₇₈₉₊₋₌₍₎ₐₑₕᵢⱼₖₗₘₙₒₚᵣₛₜᵤᵥₓ")
_SUP = str.maketrans("0123456789+-=()n", "⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻⁼⁽⁾ⁿ")


def _script(text: str, table: dict, mark: str) -> str:
    """Sub- or superscript ``text`` in Unicode where every character has one, else ``mark`` + text (h_{2/1})."""
    shifted = text.translate(table)
    return shifted if all(a != b or a in " " for a, b in zip(text, shifted, strict=True)) else f"{mark}{text}"


def plain(text: str) -> str:
    """Mathtext as plain Unicode, as matplotlib shows it: ``$m_{2}$`` -> m₂, ``$\\omega$`` -> ω, ``s$^{-1}$`` -> s⁻¹,
    ``$c_1^2$`` -> c₁²; outside ``$...$`` the text is shown as written (``half_height_1`` stays so)."""
    parts = str(text).split("$")
    if len(parts) % 2 == 0:  # an unpaired $: matplotlib shows the text as written
        return str(text)
    return "".join(_math(p) if k % 2 else p for k, p in enumerate(parts))


def _math(text: str) -> str:
    """One ``$...$`` segment as Unicode."""
    out = re.sub(r"\\([A-Za-z]+)", lambda m: GREEK.get(m.group(1), m.group(1)), text)
    out = re.sub(r"_\{([^{}]*)\}|_(\w)", lambda m: _script(m.group(1) or m.group(2), _SUB, "_"), out)
    out = re.sub(r"\^\{([^{}]*)\}|\^(\w)", lambda m: _script(m.group(1) or m.group(2), _SUP, "^"), out)
    return out.replace("{", "").replace("}", "").replace("\\,", " ").replace("\\ ", " ")


def unit_plain(ds: xr.Dataset, dim: str) -> str:
    """The units of coordinate ``dim`` as shown: 'rad s⁻¹' (a space before it), '' when it has none."""
    u = plain(units_text(str(ds[dim].attrs.get("units", "")))).replace("\u00a0", " ")
    return f" {u}" if u else ""


def axis_title(ds: xr.Dataset, dim: str, shown: str = "") -> str:
    """'common spin rate ω [rpm]': the figures' axis label (:func:`stabmap.read.plot.labels.axis_label`, ``shown``:
    the unit its ticks are shown in), one line, plain Unicode."""
    return plain(axis_label(ds, dim, width=10_000, shown=shown)).replace("\u00a0", " ")


def name(ds: xr.Dataset, dim: str) -> str:
    """The symbol of ``dim``: 'ω', 'm₂', 'h₂/h₁'."""
    return plain(symbol(ds, dim))


def value_text(ds: xr.Dataset, dim: str, value: float) -> str:
    """'ω = 406 rpm (42.5 rad s⁻¹)': a value of ``dim`` with its symbol, in the axis's display unit (rpm, Hz) when the
    scene gave one, as its axis shows it, and in the stored units."""
    shown = str(ds[dim].attrs.get("display_units", ""))
    if shown:
        return f"{name(ds, dim)} = {value / units.factor(shown):.6g} {shown} ({value:.6g}{unit_plain(ds, dim)})"
    return f"{name(ds, dim)} = {value:.6g}{unit_plain(ds, dim)}"


def span_texts(ds: xr.Dataset, dim: str, k: int) -> list[str]:
    """One line per block of ``k`` grid values of ``dim``: its value, or the first and last of its values."""
    v = np.asarray(ds[dim], dtype=float)
    out = []
    for i in range(0, len(v), k):
        part = v[i : i + k]
        if len(part) == 1:
            out.append(value_text(ds, dim, float(part[0])))
        else:
            out.append(f"{name(ds, dim)} = {part[0]:.6g} … {part[-1]:.6g}{unit_plain(ds, dim)} ({len(part)} grid values)")
    return out


def escape(text: str) -> str:
    """Text for HTML, line breaks kept."""
    return html.escape(text).replace("\n", "<br>")
