"""The paper's scenes (section 4.2) as functions that return a Scene.

Each is short on purpose: copy one, change the geometry, material or loading, and
pass it to :class:`ngfracture.run.simulation.Simulation`.

* :func:`plate`: a square glass plate with small notches on the top and bottom edges,
  pulled apart by gliding conditions on the left and right sides.
* :func:`disk`: a brittle disk with a hole around a softer, separate core whose inner
  boundary expands; contact passes the expansion on; radial cracks grow from the hole
  while the outer ring stays whole.
* :func:`disintegration`: the same disk expanded further, until it falls apart.
* :func:`beam`: a notched beam in three-point bending; its crack grows one event per load
  step at its critical load, through the peak of the load-displacement curve.
* :func:`holed_beam`: a beam in three-point bending with its notch off mid-span and a hole
  beside the crack's path: a mixed-mode crack that curves past the hole.
* :func:`bar3d`: a notched bar in tension, on tetrahedra: one crack across the ligament.
* :func:`plate3d`: the notched plate extruded to a thickness, on tetrahedra.
* :func:`shaft3d`: a glass shaft twisted about its axis, on tetrahedra: one crack along a
  helicoid, a curved crack surface.
* :func:`blocks3d`: a block pressed on another, meshed apart with non-matching grids, on
  tetrahedra: contact without cracks, the contact patch test as a run.
* :func:`sphere3d`: the disk scene as a sphere: a glass sphere with a hole around an
  expanding core shell, held outside; radial crack surfaces from the hole (Fig. 9 in 3D).
* :func:`sphere3d_free`: the same free outside, expanded until it falls apart (Fig. 10 in 3D).

Every scene judges cracks at a critical distance ``radius`` (docs/criterion.md);
``radius=None`` selects the paper's one-ring criterion.
"""
from .contact3d import BLOCKS_LOAD, blocks3d, two_blocks_mesh
from .solids import bar3d, extruded_plate_mesh, notched_bar_mesh, plate3d
from .beams import beam, holed_beam, holed_beam_mesh, notched_beam_mesh, senb_factor
from .common import (BAR_LOAD, BAR_RADIUS, BEAM_LOAD, CORE_INNER, DISINTEGRATION_RADIUS, DISK_LOAD, DISK_RADIUS, FIRST_CRACK, GLASS, HOLE,
                     PLATE_LOAD, PLATE_RADIUS)
from .disks import cored_disk_mesh, disintegration, disk
from .plates import notched_plate_mesh, plate
from .spheres import SPHERE_LOAD, cored_sphere_mesh, shells_exact, sphere3d, sphere3d_free, sphere_first_crack
from .torsion import SHAFT_LOAD, SHAFT_RADIUS, shaft3d, shaft_mesh

__all__ = ["plate", "disk", "disintegration", "beam", "holed_beam", "notched_plate_mesh", "cored_disk_mesh",
           "notched_beam_mesh", "holed_beam_mesh", "senb_factor", "GLASS", "PLATE_RADIUS", "DISK_RADIUS",
           "DISINTEGRATION_RADIUS", "HOLE", "CORE_INNER", "FIRST_CRACK", "PLATE_LOAD", "DISK_LOAD", "BEAM_LOAD",
           "SCENES", "LOAD_DESCRIPTIONS", "bar3d", "notched_bar_mesh", "plate3d", "extruded_plate_mesh", "BAR_RADIUS",
           "BAR_LOAD", "shaft3d", "shaft_mesh", "SHAFT_RADIUS", "SHAFT_LOAD", "blocks3d", "two_blocks_mesh", "BLOCKS_LOAD",
           "sphere3d", "sphere3d_free", "cored_sphere_mesh", "shells_exact", "sphere_first_crack", "SPHERE_LOAD"]

#: the scenes of ``python -m ngfracture run``
SCENES = {"plate": plate, "disk": disk, "disintegration": disintegration, "beam": beam, "holed_beam": holed_beam,
          "bar3d": bar3d, "plate3d": plate3d,
          "shaft3d": shaft3d, "blocks3d": blocks3d, "sphere3d": sphere3d, "sphere3d_free": sphere3d_free}
#: what the load parameter x of each scene is (Scene.load_description)
LOAD_DESCRIPTIONS = {"plate": PLATE_LOAD, "disk": DISK_LOAD, "disintegration": DISK_LOAD, "beam": BEAM_LOAD,
                     "holed_beam": BEAM_LOAD, "bar3d": BAR_LOAD, "plate3d": PLATE_LOAD,
                     "shaft3d": SHAFT_LOAD, "blocks3d": BLOCKS_LOAD,
                     "sphere3d": SPHERE_LOAD, "sphere3d_free": SPHERE_LOAD}

