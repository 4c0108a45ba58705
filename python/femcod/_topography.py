"""An adapter for SurfaceTopography (optional: used only when that package is installed)."""
import numpy as np

#: Length units SurfaceTopography writes, in nm.
_NM = {"m": 1e9, "mm": 1e6, "um": 1e3, "µm": 1e3, "nm": 1.0, "Å": 0.1, "A": 0.1, "pm": 1e-3}


def from_topography(topography):
    """The keyword arguments of femcod.solve for a SurfaceTopography Topography:
    ``femcod.solve(**femcod.from_topography(t), loads=[...])``. Its heights()[k, l]
    (x index k, y index l) become femcod's [i, j] = [k, l]; heights and the pixel are
    converted to nm from the topography's unit. The grid must be square with square pixels."""
    heights = np.asarray(topography.heights())
    nx, ny = topography.nb_grid_pts
    sx, sy = topography.physical_sizes
    if nx != ny:
        raise ValueError(f"femcod's grids are square: the topography has {nx} x {ny} points")
    if not np.isclose(sx / nx, sy / ny, rtol=1e-12):
        raise ValueError(f"femcod's pixels are square: {sx / nx} x {sy / ny}")
    unit = getattr(topography, "unit", None) or "nm"
    if unit not in _NM:
        raise ValueError(f"unknown length unit {unit!r} (known: {', '.join(_NM)})")
    scale = _NM[unit]
    return {"lower": heights * scale, "pixel": sx / nx * scale}
