import time, ngfracture as nf
scene = nf.scenes.plate(maxh=0.034 / 8)
print("ne", scene.mesh.ne, flush=True)
t = time.time()
res = nf.Simulation(scene, pictures="none").run()
s = res.summary
first = next(h for h in s["history"] if h["split_vertices"] > 0)
print(round(time.time() - t, 1), res.reason, "splits", s["n_split_vertices"], "frag", s["n_fragments"], "crack", s["history"][-1]["crack_length"], "first x", first["x"])
