"""What a run writes: VTK time series, pictures, summaries.

vtk     VTK time series and crack edges, headless PNG, fragment-size plot, summary JSON
vtkxml  VTK XML files (.vtu, .vtp) from numpy arrays, without VTK
"""
