#!/usr/bin/env python3
"""Regenerates the measured-error tables behind the presets' budgets.

    cargo test -p shadow-tests --test conformance -- conformance/ --test-threads 1 \
        | grep -E '^[a-z]' | python3 scripts/measure_budgets.py FILE.rs PRESET=CONST ...

Each `PRESET=CONST` pair rewrites `const CONST: &[(&str, [f64; 5])] = &[...]` in FILE.rs with
the errors the suite printed for PRESET (rmse, penumbra rmse, bias, max, share > 0.1): a scene
the run measured gets its new row (in place, or appended), the other rows stay, so a run filtered
to one new scene adds it. Budgets are these numbers with the margins of `Budget::from_measured`. Only rerun this when a change is
meant to move a technique's error (a new sampler, a fixed bug), and say so in the commit.
"""
import sys


def main() -> None:
    path, pairs = sys.argv[1], dict(a.split("=") for a in sys.argv[2:])
    rows = {}
    for line in sys.stdin:
        # With one test thread libtest prints `test NAME ... ` before the case's own line.
        if line.startswith("test ") and " ... " in line:
            line = line.split(" ... ", 1)[1]
        t = line.split()
        if len(t) < 12 or t[2] != "rmse":
            continue
        vals = [float(t[3]), float(t[5]), float(t[7]), float(t[9]), float(t[11])]
        rows.setdefault(t[0], []).append((t[1], vals))
    src = open(path).read()
    for preset, const in pairs.items():
        head = f"const {const}: &[(&str, [f64; 5])] = &["
        a = src.index(head)
        b = src.index("];", a)
        old = src[a + len(head) : b]
        # The rows already there, in order (rustfmt may have split a row over lines).
        kept = []
        for row in old.replace("\n", " ").split("),"):
            row = row.strip().lstrip("(").strip()
            if row.startswith('"'):
                scene = row[1 : row.index('"', 1)]
                nums = row[row.index("[") + 1 : row.index("]")]
                kept.append((scene, [float(x) for x in nums.split(",")]))
        new = dict(rows.get(preset, []))
        merged = [(sc, new.pop(sc, v)) for sc, v in kept] + list(new.items())
        body = "\n".join(
            f'    ("{scene}", [{v[0]:.4f}, {v[1]:.4f}, {v[2]:.4f}, {v[3]:.3f}, {v[4]:.4f}]),'
            for scene, v in merged
        )
        src = src[:a] + head + "\n" + body + "\n" + src[b:]
    open(path, "w").write(src)


if __name__ == "__main__":
    main()
