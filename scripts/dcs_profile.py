#!/usr/bin/env python3
"""Instructions of one estimate by function: the callgrind profile of a run with one estimate
minus the profile of the same run with none, as `scripts/dcs_instructions.sh` leaves them.

    scripts/dcs_instructions.sh bunny dcs-64        # writes /tmp/dcs_cg_1.out, /tmp/dcs_cg_0.out
    python3 scripts/dcs_profile.py [--inclusive] [--top N] [ONE ZERO]

Without `--inclusive` each function's own instructions, code inlined into it included (so
`sse.rs:...square_pairs` is the vector intrinsics inlined into `square_pairs`, filed under the
intrinsics' source); with it, the instructions of the calls it makes too. Loading the scene,
rendering the view samples and `prepare` are in both profiles and cancel, so the exclusive
figures sum to the `dcs_instructions.sh` total. Needs `callgrind_annotate` (valgrind).
"""
import re
import subprocess
import sys


def load(path: str, inclusive: bool) -> dict:
    out = subprocess.run(
        [
            "callgrind_annotate",
            f"--inclusive={'yes' if inclusive else 'no'}",
            "--auto=no",
            "--threshold=100",
            path,
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    counts: dict = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+) (?:\([^)]*\))?\s+(\S.*)", line)
        if not m or "PROGRAM TOTALS" in line:
            continue
        # One name per function whatever the toolchain's hash or the binary's path.
        name = re.sub(r"/rustc/[0-9a-f]+/", "", m.group(2))
        name = re.sub(r"\s*\[[^\]]*\]\s*$", "", name)
        name = re.sub(r"^.*/\.cargo/registry/src/[^/]+/", "", name)
        name = re.sub(r"^/\S*?/(shadow-[a-z]+/|xtask/|tests/)", r"\1", name)
        n = int(m.group(1).replace(",", ""))
        # Exclusive counts of one function under several names add up; inclusive ones
        # overlap (a function's total and the part of it filed under one source file).
        counts[name] = max(counts.get(name, 0), n) if inclusive else counts.get(name, 0) + n
    return counts


def main() -> None:
    args = sys.argv[1:]
    inclusive = "--inclusive" in args
    args = [a for a in args if a != "--inclusive"]
    top = 40
    if "--top" in args:
        i = args.index("--top")
        top = int(args[i + 1])
        del args[i : i + 2]
    one, zero = args if args else ("/tmp/dcs_cg_1.out", "/tmp/dcs_cg_0.out")
    a, b = load(one, inclusive), load(zero, inclusive)
    diff = {k: a.get(k, 0) - b.get(k, 0) for k in a.keys() | b.keys()}
    if not inclusive:
        print(f"{sum(diff.values()) / 1e6:10.1f} M  one estimate in all")
    for name, v in sorted(diff.items(), key=lambda x: -x[1])[:top]:
        print(f"{v / 1e6:10.1f} M  {name}")


if __name__ == "__main__":
    main()
