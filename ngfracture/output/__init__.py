"""What a run writes: VTK time series, pictures, JSON, all through one atomic writer.

atomic      files written atomically (temporary file, fsync, rename): bytes, JSON
vtk         a mesh and its fields as VTK data (pyvista objects or numpy arrays)
solid_vtk   the same for tetrahedral (3D) meshes; vtk, timeseries and pictures pass them on
vtkxml      VTK XML files (.vtu, .vtp) from numpy arrays, without VTK
timeseries  ``TimeSeriesWriter``: one .vtu and one .vtp per step, .pvd collections
pictures    ``final.png`` of the deformed pieces and the fragment-size plot, headless
solid_pictures  ``final.png`` of a 3D run: the shaded surface of the deformed pieces
curves      the load-displacement curve: ``force_displacement.csv`` and ``.png``

The public names of these modules are re-exported here.
"""
from .atomic import *      # noqa: F401,F403
from .vtk import *         # noqa: F401,F403
from .timeseries import *  # noqa: F401,F403
from .pictures import *    # noqa: F401,F403
from .solid_vtk import *   # noqa: F401,F403
from .solid_pictures import *  # noqa: F401,F403
from .curves import *      # noqa: F401,F403
from . import atomic as _atomic, curves as _curves, pictures as _pictures, timeseries as _timeseries, vtk as _vtk
from . import solid_pictures as _solid_pictures, solid_vtk as _solid_vtk

__all__ = (list(_atomic.__all__) + list(_vtk.__all__) + list(_timeseries.__all__) + list(_pictures.__all__)
           + list(_solid_vtk.__all__) + list(_solid_pictures.__all__) + list(_curves.__all__))
