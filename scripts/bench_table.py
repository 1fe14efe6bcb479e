#!/usr/bin/env python3
"""Formats Google Benchmark JSON from gssm_bench_latency as a Markdown table,
each latency as a ratio to the EKF measured in the same run."""
import json, sys, datetime, platform, os, subprocess

data = json.load(open(sys.argv[1]))
cmd = sys.argv[2]
machine = subprocess.run([os.path.join(os.path.dirname(os.path.abspath(__file__)), "machine")],
                         capture_output=True, text=True, check=True).stdout.strip()
rows = {b["name"]: b for b in data["benchmarks"]}
ekf = next(b for n, b in rows.items() if "/ekf/" in n)
us = lambda s: f"{s * 1e6:.1f}"
print("# Benchmark results\n")
print(f"- machine: {machine}")
print(f"- date: {datetime.date.today().isoformat()}")
print(f"- command: `{cmd}` (via `scripts/bench`)")
print("- scenario: radar paper scenario, 2000 steps of T = 0.05 s; per-update wall time of `addMeasurement`\n")
print("| estimator | median (µs) | p99 (µs) | max (µs) | median / EKF | p99 / EKF |")
print("| --- | --- | --- | --- | --- | --- |")
for name, b in rows.items():
    if "median_s" not in b:
        continue
    label = name.split("/")[1].replace("_", " ")
    print(f"| {label} | {us(b['median_s'])} | {us(b['p99_s'])} | {us(b['max_s'])} | "
          f"{b['median_s'] / ekf['median_s']:.1f}× | {b['p99_s'] / ekf['p99_s']:.1f}× |")
for name, b in rows.items():
    if not name.startswith("BM_BatchSolve/"):
        continue
    steps = int(name.split("/")[1])
    ms = lambda s: f"{s * 1e3:.1f}"
    total = b["solve_s"] + b["marginals_s"]
    print(f"\n## Batch MAP, {steps:,} radar steps (`BM_BatchSolve`, same run)\n")
    print("| part | median (ms) |")
    print("| --- | --- |")
    print(f"| `BatchSolver::solve` (LM from the EKF's estimates, {int(b['iterations'])} iterations; a new solver each time) | {ms(b['solve_s'])} |")
    print(f"| every step's marginal covariance | {ms(b['marginals_s'])} |")
    print(f"| solve + marginals | {ms(total)} |")
    print(f"| EKF pass over the same measurements (baseline) | {ms(b['ekf_s'])} |")
    print(f"\nSolve + marginals = {total / b['ekf_s']:.2f}× the EKF pass; "
          f"{b['solve_faults']:.0f} page faults per solve (memory the allocator returned between solves "
          f"is fresh again; the first solve of a fresh process: `gssm_history_probe {steps} batch` below).")

if len(sys.argv) > 3:
    size = json.load(open(sys.argv[3]))
    by = {}
    for b in size["benchmarks"]:
        _, method, nc, nb = b["name"].split("/")[:4]
        by[(method, int(nc), int(nb))] = b["median_s"]
    print("\n## State size: synthetic linear GSSM, fixed-lag (w = 10) vs EKF\n")
    print(f"Command: `{sys.argv[4]}`. Median per-update latency (µs), and the ratio fixed-lag / EKF.\n")
    print("| n_c \\ n_b | " + " | ".join(str(nb) for nb in (1, 4, 16, 64)) + " |")
    print("| --- | --- | --- | --- | --- |")
    for nc in (1, 4, 16, 64):
        cells = []
        for nb in (1, 4, 16, 64):
            e, f = by[("ekf", nc, nb)], by[("fixed_lag_w10", nc, nb)]
            cells.append(f"{f*1e6:.0f} vs {e*1e6:.0f} ({f/e:.1f}×)")
        print(f"| {nc} | " + " | ".join(cells) + " |")
if len(sys.argv) > 5:
    print("\n## History length and memory (`build/bench/gssm_history_probe STEPS METHOD`)\n")
    print("```")
    print(open(sys.argv[5]).read().rstrip())
    print("```")
