"""Write ``N`` campaigns of the apart testbed: ``python -m testbeds.apart.campaigns --seed S
--n N --out DIR [--start I] [--jobs J]``. Campaign ``i`` depends on ``(S, i)`` only, so
``--start`` extends a bench without changing the campaigns already written.
docs/validation/gap-apart.md."""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from testbeds.apart.campaign import write_campaign_folder


def _one(job) -> str:
    out, seed, index = job
    doc = write_campaign_folder(out, seed, index)
    return f"{doc['campaign']}: {len(doc['runs'])} runs"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m testbeds.apart.campaigns",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--n", type=int, required=True, help="number of campaigns")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--start", type=int, default=0, help="index of the first campaign")
    parser.add_argument("--jobs", type=int, default=1, help="campaigns written at a time")
    args = parser.parse_args(argv)
    if args.n < 1 or args.start < 0 or args.jobs < 1:
        parser.error("--n and --jobs must be >= 1, --start >= 0")
    start = time.perf_counter()
    jobs = [(args.out, args.seed, i) for i in range(args.start, args.start + args.n)]
    if args.jobs == 1:
        for line in map(_one, jobs):
            print(line, flush=True)
    else:
        with ProcessPoolExecutor(args.jobs) as pool:
            for line in pool.map(_one, jobs):
                print(line, flush=True)
    print(f"{args.n} campaigns in {time.perf_counter() - start:.0f} s under {args.out} "
          f"(truths in {args.out / 'truth'}: keep them from the diagnosis)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
