"""Memory series of the soak tests (tests/soak/soak_*.py): how a series of
resident-set sizes is judged, in plain Python so that Blender's interpreter
and the system one both run it.

A series is one RSS figure (KiB) per step (a render, a viewport redraw
cycle). The first `warmup` steps are left out: caches (compiled programs,
the patch cache, the allocator's arenas, Blender's render result) fill
during them. After that, two figures must stay within their bounds:

- growth: the median of the last `window` steps minus the median of steps
  warmup .. warmup + window (medians, so that one step's transient peak
  does not decide);
- slope: the least-squares slope over every step after the warm-up, in KiB
  per step.

A leak of `leak_kib` per step is shown to fail the same bounds by adding it
to the measured series (leak_detected): the bounds would catch such a leak
on this very run's noise.
"""

import json
import statistics


def rss_kib(pid="self"):
    """VmRSS of a process in KiB (Linux /proc), or None once it is gone."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except (FileNotFoundError, ProcessLookupError):
        return None
    return None


def least_squares_slope(xs, ys):
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    return sxy / sxx if sxx else 0.0


def residual_stdev(xs, ys, slope):
    """Standard deviation of the series about its fitted line (the noise)."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    res = [y - (my + slope * (x - mx)) for x, y in zip(xs, ys)]
    return statistics.pstdev(res)


def judge(series, warmup, window, growth_bound_kib, slope_bound_kib, steps=None):
    """Figures of a series and whether they are within the bounds. `steps`
    gives each value's position in steps (fractional where the series is
    sampled in time, soak_cli.py); by default value i is step i."""
    steps = list(range(len(series))) if steps is None else list(steps)
    last = steps[-1] if steps else 0
    early = [v for x, v in zip(steps, series) if warmup <= x < warmup + window]
    late = [v for x, v in zip(steps, series) if x > last - window]
    after = [(x, v) for x, v in zip(steps, series) if x >= warmup]
    if last < warmup + 2 * window or len(early) < 5 or len(late) < 5 or len(after) < 20:
        raise ValueError(f"a series of {len(series)} values over {last:.0f} steps is too short for warm-up "
                         f"{warmup} and windows of {window} steps")
    xs, ys = [x for x, _ in after], [v for _, v in after]
    slope = least_squares_slope(xs, ys)
    result = {
        "steps": len(series) if len(steps) == len(series) and steps == list(range(len(series))) else round(last),
        "values": len(series),
        "first_kib": series[0],
        "after_warmup_kib": ys[0],
        "last_kib": series[-1],
        "peak_kib": max(series),
        "early_median_kib": statistics.median(early),
        "late_median_kib": statistics.median(late),
        "slope_kib_per_step": slope,
        "noise_stdev_kib": residual_stdev(xs, ys, slope),
        "warmup": warmup,
        "window": window,
        "growth_bound_kib": growth_bound_kib,
        "slope_bound_kib_per_step": slope_bound_kib,
    }
    result["growth_kib"] = result["late_median_kib"] - result["early_median_kib"]
    result["failures"] = []
    if result["growth_kib"] > growth_bound_kib:
        result["failures"].append(f"memory grew {result['growth_kib']:.0f} KiB from steps {warmup}-{warmup + window} "
                                  f"to the last {window} (bound {growth_bound_kib} KiB)")
    if slope > slope_bound_kib:
        result["failures"].append(f"memory slope {slope:.1f} KiB/step after the warm-up (bound {slope_bound_kib})")
    return result


def leak_detected(series, leak_kib, warmup, window, growth_bound_kib, slope_bound_kib, steps=None):
    """Whether the bounds fail on this series plus a leak of leak_kib per step."""
    steps = list(range(len(series))) if steps is None else list(steps)
    leaky = [v + leak_kib * x for x, v in zip(steps, series)]
    return bool(judge(leaky, warmup, window, growth_bound_kib, slope_bound_kib, steps)["failures"])


def summary_text(title, result, extra=()):
    """The result as the lines of bench/results/soak_*.txt."""
    lines = [title]
    lines += [f"  {k}: {v:.1f}" if isinstance(v, float) else f"  {k}: {v}" for k, v in result.items()
              if k not in ("failures", "series_kib")]
    lines += [f"  {line}" for line in extra]
    lines.append("  verdict: " + ("FAIL: " + "; ".join(result["failures"]) if result["failures"] else "pass"))
    return "\n".join(lines) + "\n"


def write_json(path, result):
    with open(path, "w") as f:
        json.dump(result, f, indent=1)
