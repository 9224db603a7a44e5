from scipy.io import loadmat

mat = loadmat("session.mat", simplify_cells=True)  # MAT v5, bellows' default
iterations = mat["iterations"]                      # a list of dicts, one per iteration
last = iterations[-1]
print(f"{len(iterations)} iterations, last RMS {last['rms_deg']:.4f} deg")
box = mat["black_boxes"]  # one fault: a dict; several: a list of dicts
box = box if isinstance(box, dict) else box[-1]
print(f"black box: {box['fault']}, last state {box['ticks']['state'][-1]}")
