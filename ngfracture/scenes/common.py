"""What the built-in scenes share: the paper's glass, the critical distances, the load descriptions."""
import math

#: the paper's glass: E = 5 GPa, nu = 0.18, critical principal strain 1.3817e-4
GLASS = dict(E=5e9, nu=0.18, critical=1.3817e-4)

#: radii of the disk's hole and of the core ring's inside (the disk's radius is 1)
HOLE, CORE_INNER = 0.25, 0.125
#: expansion of the core's inside that first cracks the glass disk: the hole's hoop strain
#: u_r / r reaches the critical strain at u_r(hole) ~ critical * hole, and the softer core
#: ring is squeezed too, about 1.5 times that at its inside
FIRST_CRACK = 1.5 * GLASS["critical"] * HOLE

#: critical distances of the scenes' glass (docs/criterion.md): the material length over which
#: the crack criterion judges the stress. A material constant (with E and the critical strain
#: it sets the toughness K_c = E critical sqrt(2 pi r)); each scene's value keeps its default
#: mesh fine enough (h <= r/4 where the plate's crack runs, h <= r/2 in the disks)
PLATE_RADIUS, DISK_RADIUS, DISINTEGRATION_RADIUS = 0.04, 0.12, 0.16
#: the notched bar's critical distance (3D): its default mesh is r/2 at the crack plane
BAR_RADIUS = 0.08

#: the load parameters, for Scene.load_description and the command line's --help
PLATE_LOAD = "total extension of the unit plate (length; equals the mean strain)"
DISK_LOAD = "radial displacement of the core's inner boundary (length; the disk's radius is 1)"
BAR_LOAD = "extension of the bar (length; the bar is 2 long)"
BEAM_LOAD = "downward displacement of the loading pad on the beam's top (length; the beam's height is 1)"


def positive(name, value):
    """A scene parameter that must be a finite number > 0, as a float.

    Parameters
    ----------
    name : str
        The parameter's name, for the error.
    value : object

    Returns
    -------
    float

    Raises
    ------
    ValueError
        ``value`` is not a finite number > 0 (booleans included).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)

