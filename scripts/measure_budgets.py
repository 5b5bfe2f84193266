#!/usr/bin/env python3
"""Regenerates the measured-error tables behind the presets' budgets.

    cargo test -p shadow-tests --test conformance -- conformance/ --test-threads 1 \
        | grep -E '^[a-z]' | python3 scripts/measure_budgets.py FILE.rs PRESET=CONST ...
    cargo xtask conformance --quick --scenes corpus --out out/conf-corpus
    python3 scripts/measure_budgets.py --report out/conf-corpus/report.json --corpus \
        FILE.rs PRESET=CONST PRESET@fs=CONST ...

Each `PRESET=CONST` pair rewrites `const CONST: &[(&str, [f64; 5])] = &[...]` in FILE.rs with
the errors measured for PRESET (rmse, penumbra rmse, bias, max, share > 0.1), and each
`PRESET@fs=CONST` pair `const CONST: &[(&str, f64)]` with its false-shadow share. A scene the
run measured gets its new row (in place, or appended), the other rows stay, so a run filtered
to one new scene adds it. Budgets are these numbers with the margins of `Budget::from_measured`.

The measurements come from the test suite's lines on standard input, or with `--report` from
the `report.json` of `cargo xtask conformance`.

`--corpus` folds every corpus scene's row into the one `corpus` row (`shadow_presets::
CORPUS_ROW`): each measure its largest over the scenes (bias: the signed value of the largest
magnitude). `--max` keeps, measure by measure, the larger of the row already in the table and
the new one: how a table holds the larger error of two image sizes (the GPU presets run at
48 x 36 in `cargo test` and 128 x 96 in the main job).

Only rerun this when a change is meant to move a technique's error (a new sampler, a fixed bug),
and say so in the commit.
"""
import json
import sys

CORPUS_ROW = "corpus"


def rows_from_tests(lines):
    """(preset, scene, [rmse, pen, bias, max, share], false shadow) from the suite's lines."""
    out = []
    for line in lines:
        # With one test thread libtest prints `test NAME ... ` before the case's own line.
        if line.startswith("test ") and " ... " in line:
            line = line.split(" ... ", 1)[1]
        t = line.split()
        if len(t) < 14 or t[2] != "rmse" or t[12] != "fs":
            continue
        vals = [float(t[3]), float(t[5]), float(t[7]), float(t[9]), float(t[11])]
        out.append((t[0], t[1], vals, float(t[13])))
    return out


def rows_from_report(path):
    """The same from `cargo xtask conformance`'s report.json (cases that ran)."""
    out = []
    for c in json.load(open(path))["cases"]:
        m = c.get("metrics")
        if not m:
            continue
        vals = [m["rmse"], m.get("penumbra_rmse") or 0.0, m["bias"], m["max_abs"], m["share_over_0_1"]]
        out.append((c["technique"], c["scene"], vals, c.get("false_shadow", 0.0)))
    return out


def fold_max(a, b):
    """Measure by measure the larger; for bias (index 2 of five) the larger magnitude."""
    if isinstance(a, float):
        return max(a, b)
    return [
        (x if abs(x) >= abs(y) else y) if i == 2 and len(a) == 5 else max(x, y)
        for i, (x, y) in enumerate(zip(a, b))
    ]


def fmt(v):
    if isinstance(v, float):
        return f"{v:.4f}"
    return f"[{v[0]:.4f}, {v[1]:.4f}, {v[2]:.4f}, {v[3]:.3f}, {v[4]:.4f}]"


def parse_table(body):
    """The rows already in a table body, in order (rustfmt may have split a row over lines)."""
    kept = []
    for row in body.replace("\n", " ").split("),"):
        row = row.strip().lstrip("(").strip()
        if not row.startswith('"'):
            continue
        scene = row[1 : row.index('"', 1)]
        rest = row[row.index('"', 1) + 1 :].strip().lstrip(",").strip().rstrip(")").rstrip(",")
        if "[" in rest:
            nums = rest[rest.index("[") + 1 : rest.index("]")]
            kept.append((scene, [float(x) for x in nums.split(",")]))
        else:
            kept.append((scene, float(rest)))
    return kept


def main() -> None:
    args = sys.argv[1:]
    report, corpus, keep_max = None, False, False
    while args and args[0].startswith("--"):
        flag = args.pop(0)
        if flag == "--report":
            report = args.pop(0)
        elif flag == "--corpus":
            corpus = True
        elif flag == "--max":
            keep_max = True
        else:
            sys.exit(f"unknown option {flag}")
    path, pairs = args[0], dict(a.split("=") for a in args[1:])
    measured = rows_from_report(report) if report else rows_from_tests(sys.stdin)
    rows = {}
    for preset, scene, vals, fs in measured:
        for key, v in ((preset, vals), (preset + "@fs", fs)):
            table = rows.setdefault(key, {})
            name = CORPUS_ROW if corpus and scene.startswith("corpus-") else scene
            table[name] = fold_max(table[name], v) if name in table else v
    src = open(path).read()
    for key, const in pairs.items():
        kind = "f64" if key.endswith("@fs") else "[f64; 5]"
        head = f"const {const}: &[(&str, {kind})] = &["
        a = src.index(head)
        b = src.index("];", a)
        kept = parse_table(src[a + len(head) : b])
        new = dict(rows.get(key, {}))
        if not new:
            sys.exit(f"no measurement of {key}")
        merged = []
        for sc, v in kept:
            if sc in new:
                n = new.pop(sc)
                v = fold_max(v, n) if keep_max else n
            merged.append((sc, v))
        merged += list(new.items())
        body = "\n".join(f'    ("{scene}", {fmt(v)}),' for scene, v in merged)
        src = src[:a] + head + "\n" + body + "\n" + src[b:]
    open(path, "w").write(src)


if __name__ == "__main__":
    main()
