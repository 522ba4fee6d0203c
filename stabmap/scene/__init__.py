"""What every system's scene is made of: numbers checked against their parameter, grid axes, TOML text.

A scene is data: a frozen dataclass of its system (``stabmap.systems.<name>.scene``),
a TOML file on disk, and the same TOML stored back into every atlas.  This
package holds the parts that no system names: ``values`` (a parameter's units,
limits and the one check of a number), ``grid`` (the axes of a scan) and
``text`` (TOML in and out).  Which system a TOML file describes, and how it is
validated, is ``stabmap.systems``'s business.
"""
