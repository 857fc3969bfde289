"""Automaton compile time per task: CraftSuite cold and cached, beside flloat.

Usage: python benchmarks/automata.py [--flloat-timeout SECONDS]

Each measurement runs in a fresh process with an empty (cold) or filled (cached) cache
directory, so imports and first-call costs are counted the way a user meets them.
flloat (the reference, ``LTLfParser()(f).to_automaton()``) runs under a time limit.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time

ROOT_CODE = """
import json, sys, time
from craftsuite.spec import builtin_specs
from craftsuite.automata import compile_ltlf
spec = builtin_specs()[sys.argv[1]]
t = time.perf_counter()
a = compile_ltlf(spec.formula, spec.proposition_names)
print(json.dumps({"seconds": time.perf_counter() - t, "size": a.size()}))
"""

FLLOAT_CODE = """
import json, sys, time
from craftsuite.spec import builtin_specs
from flloat.parser.ltlf import LTLfParser
spec = builtin_specs()[sys.argv[1]]
t = time.perf_counter()
dfa = LTLfParser()(spec.formula).to_automaton()
print(json.dumps({"seconds": time.perf_counter() - t, "states": len(dfa.states)}))
"""


def run(code, task, env=None, timeout=None):
    try:
        out = subprocess.run([sys.executable, "-c", code, task], capture_output=True, text=True,
                             env=env, timeout=timeout, check=True)
    except subprocess.TimeoutExpired:
        return None
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flloat-timeout", type=float, default=120.0)
    parser.add_argument("--tasks", nargs="*", default=["BlindCraftsman", "DungeonQuest", "DiamondMine"])
    args = parser.parse_args()

    import os
    print("| task | propositions | states/transitions (paper's count) | CraftSuite cold | "
          "CraftSuite cached | flloat 0.3.0 |")
    print("|---|---|---|---|---|---|")
    for task in args.tasks:
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, CRAFTSUITE_CACHE_DIR=cache)
            cold = run(ROOT_CODE, task, env)
            cached = min((run(ROOT_CODE, task, env) for _ in range(5)), key=lambda r: r["seconds"])
        t = time.perf_counter()
        ref = run(FLLOAT_CODE, task, timeout=args.flloat_timeout)
        flloat = (f"{ref['seconds']:.2f} s ({ref['states']} states)" if ref
                  else f"did not finish in {time.perf_counter() - t:.0f} s")
        from craftsuite.spec import builtin_specs
        n = len(builtin_specs()[task].propositions)
        s, e = cold["size"]
        print(f"| {task} | {n} | {s}/{e} | {cold['seconds'] * 1000:.0f} ms | "
              f"{cached['seconds'] * 1000:.1f} ms | {flloat} |", flush=True)


if __name__ == "__main__":
    main()
