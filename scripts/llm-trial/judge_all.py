"""Runs every judge on OUTDIR/<id>.npy; prints a line per task and the count right.

usage: python3 judge_all.py OUTDIR   (numpy needed; OUTDIR as run_all.sh writes it)
"""
import json, os, sys, re
import numpy as np
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from judges import JUDGES
out = sys.argv[1]
tasks = json.load(open(os.path.join(HERE, "tasks.json")))
right = 0
rows = []
for t in tasks:
    tid = t["id"]
    try:
        j = np.load(f"{out}/{tid}.npy")
    except Exception as e:
        rows.append((tid, None, f"no output: {e}", None)); continue
    ok, why = JUDGES[tid](j)
    # met / plausible from the run's meta
    met = plaus = None
    try:
        meta = json.load(open(f"{out}/{tid}.meta.json"))
        m = meta.get("meta", meta)
        p = m.get("plausibility")
        plaus = p.get("ok") if p else None
        errs = m.get("errors") or m.get("statement_errors")
    except Exception:
        pass
    log = open(f"{out}/{tid}.log").read()
    mt = re.search(r"\| \*\*total\*\* \|[^|]*\|[^|]*\| ([0-9.]+) \|", log)
    met = mt and float(mt.group(1)) < 1e-3
    right += bool(ok)
    rows.append((tid, ok, why, (met, plaus)))
for tid, ok, why, mp in rows:
    print(f"{tid} {'RIGHT' if ok else 'wrong'} met={mp[0] if mp else None} plausible={mp[1] if mp else None} :: {why}")
print(f"right by the judge: {right}/{len(tasks)}")
