"""PlotJuggler's CSV loader needs a time column that increases row by row: check that every
per-iteration file and black box of the session in ./session has one."""
import glob

import pandas as pd

files = sorted(glob.glob("session/iterations/*.csv") + glob.glob("session/faults/*.csv"))
for name in files:
    time = pd.read_csv(name).time_s
    assert time.is_monotonic_increasing and time.is_unique, name
print(f"{len(files)} files with an increasing time_s")
