# WIP probe (not a benchmark yet): the plate with netgen-refined notch zones and refinement ahead of tips.
# Usage: NGF_GEOMETRIC_ONLY=1 PYTHONPATH=. python benchmarks/adaptive_plate_probe.py 0.1 True
import sys, time, dataclasses, warnings
import numpy as np
import ngfracture as nf
from ngfracture.scenes import notched_plate_mesh
from ngfracture.fracture.crack_graph import crack_graph
maxh, refine = float(sys.argv[1]), eval(sys.argv[2])
scene = nf.scenes.plate()
scene = dataclasses.replace(scene, mesh=notched_plate_mesh(maxh, notch_maxh=0.01, notch_zone=0.12), refine=refine)
print("start ne", scene.mesh.ne, flush=True)
t = time.time()
res = nf.Simulation(scene, pictures="none", out="/tmp/ar_out2", force=True).run()
s = res.summary
g = crack_graph(res.state.arrays)
first = next(h for h in s["history"] if h["split_vertices"] > 0)
print(round(time.time()-t,1), res.reason, "steps", s["n_steps"], "splits", s["n_split_vertices"], "frag", s["n_fragments"], "ne", res.state.arrays.triangles.shape[0])
print("first crack x", first["x"], "crack length", s.get("crack_length", None) or s["history"][-1]["crack_length"], "tips", len(g.tips), "junctions", len(g.junctions), "tipres", s.get("max_tip_resolution"))
print({k: round(v, 2) for k, v in s["timings"].items()})
