import pandas as pd

samples = pd.read_csv("session.csv")          # every iteration's samples, stacked
summary = pd.read_csv("session_summary.csv")  # one row per iteration
last = samples[samples.iteration == summary.iteration.max()]
rms = (last.error_deg.iloc[1:] ** 2).mean() ** 0.5  # e(1..N): sample 0 is not in the RMS
print(f"{len(summary)} iterations, last RMS {rms:.4f} deg")
box = pd.read_csv("session_blackbox.csv")     # only when the session had a fault
fault = box[box.fault != "none"].iloc[-1]
print(f"black box: {fault.fault} at tick {fault.tick}")
