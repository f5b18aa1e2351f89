"""Reliability under hostile input: seeded mutations of real runs (``bench.fuzz_inputs``)
through the pipeline as ``swtlab process`` runs it (``bench.fuzz_outcome``).

Prints inputs fuzzed, unhandled exceptions, hangs (over the time limit) and nonsense (a
physically impossible value marked ok), per kind of input, and the first faults found.
Full: 10,500 inputs (about 8 min on one core); ``--quick``: 600.
"""

from __future__ import annotations

import time
import warnings
from collections import Counter, defaultdict
from collections.abc import Iterable

from bench.fuzz_inputs import case
from bench.fuzz_outcome import run_case

SEED = 17
FAULTS = ("unhandled", "hang", "nonsense")


def fuzz(indices: Iterable[int], seed: int = SEED
         ) -> tuple[dict[str, Counter], list[tuple[int, str, str, str]]]:
    """Outcome counts per kind of input over cases ``indices`` of ``seed``, and the faults
    as (index, kind, what was mutated, outcome: detail)."""
    counts: dict[str, Counter] = defaultdict(Counter)
    faults = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i in indices:
            item = case(seed, i)
            outcome = run_case(item)
            counts[item.kind][outcome.kind] += 1
            if outcome.kind in FAULTS:
                faults.append((i, item.kind, item.what, f"{outcome.kind}: {outcome.detail}"))
    return counts, faults


def main(quick: bool) -> dict:
    n = 600 if quick else 10_500
    start = time.perf_counter()
    counts, faults = fuzz(range(n))
    seconds = time.perf_counter() - start
    total = sum(counts.values(), Counter())
    print(f"{'input kind':<12} {'inputs':>7} {'refused':>8} {'ok':>6} {'flagged':>8} "
          f"{'no phase':>9} {'unhandled':>10} {'hangs':>6} {'nonsense':>9}")
    for kind, c in sorted(counts.items()) + [("all", total)]:
        print(f"{kind:<12} {sum(c.values()):>7} {c['refused']:>8} {c['ok']:>6} "
              f"{c['flagged']:>8} {c['no_stable_phase']:>9} {c['unhandled']:>10} "
              f"{c['hang']:>6} {c['nonsense']:>9}")
    print(f"inputs fuzzed {n} (seed {SEED}), unhandled {total['unhandled']}, hangs "
          f"{total['hang']}, nonsense {total['nonsense']}; {seconds:.0f} s")
    for fault in faults[:20]:
        print("  fault:", *fault)
    return {"inputs": n, "seed": SEED, "unhandled": total["unhandled"],
            "hangs": total["hang"], "nonsense": total["nonsense"],
            "outcomes": dict(total), "seconds": seconds,
            "faults": [list(f) for f in faults[:100]]}
