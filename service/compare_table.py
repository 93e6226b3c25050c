"""A comparison (the body ``POST /v1/trajectories/compare`` answers) as a table for a
terminal (``toptraj compare``): a row per method with its duration (s), its ratio to the
fastest method's, its highest peak utilization (peak |value| / limit over every joint and
limit, with the limit's kind; 1 is at the limit), its number of warnings and its solve time
(ms); a method that failed shows its status and title in place of its figures, and its detail
below the table."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from toptraj.service.formats import TOLERANCE_PERCENT

#: The table's columns: header and alignment (``<`` left, ``>`` right).
COLUMNS = (("method", "<"), ("duration (s)", ">"), ("× fastest", ">"), ("peak utilization", "<"), ("warnings", ">"), ("solve (ms)", ">"))


def peak(utilization: Mapping[str, Sequence[float] | None]) -> tuple[float, str] | None:
    """The highest peak utilization over every limit and joint, and the limit's kind (the first
    kind in ``utilization``'s order on a tie); ``None`` when there is none."""
    best: tuple[float, str] | None = None
    for kind, values in utilization.items():
        for value in values or ():
            if value is not None and (best is None or value > best[0]):
                best = (float(value), kind)
    return best


def _row(result: Mapping, fastest: float | None) -> list[str]:
    """The cells of one method's row."""
    if result.get("error") is not None or result.get("duration") is None:
        error = result.get("error") or {}
        return [result["method"], f"failed: {error.get('status', '')} {error.get('title', '')}".rstrip(), "", "", "", ""]
    duration = float(result["duration"])
    top = peak(result.get("peak_utilization") or {})
    return [
        result["method"],
        f"{duration:.4f}",
        "" if not fastest else f"{duration / fastest:.3f}",
        "" if top is None else f"{top[0]:.4f} {top[1]}",
        str(len(result.get("warnings") or [])),
        "" if result.get("solve_ms") is None else f"{float(result['solve_ms']):.1f}",
    ]


def compare_table(answer: Mapping) -> str:
    """The comparison ``answer`` (``{"results": [...]}``) as aligned text, a line per method,
    then a line per failed method with its detail and a note on the columns."""
    results = answer["results"]
    durations = [float(r["duration"]) for r in results if r.get("error") is None and r.get("duration") is not None]
    fastest = min(durations) if durations else None
    rows = [[header for header, _ in COLUMNS]] + [_row(result, fastest) for result in results]
    widths = [max(len(row[k]) for row in rows if k == 0 or not row[1].startswith("failed")) for k in range(len(COLUMNS))]
    lines = []
    for row in rows:
        if row[1].startswith("failed"):
            lines.append(f"{row[0]:<{widths[0]}}  {row[1]}")
            continue
        cells = [f"{cell:{align}{width}}" for cell, (_, align), width in zip(row, COLUMNS, widths)]
        lines.append("  ".join(cells).rstrip())
    for result in results:
        if result.get("error") is not None:
            lines.append(f"{result['method']}: {result['error'].get('detail', '')}")
    lines += [
        "× fastest: duration / the shortest duration. Peak utilization: the highest peak |value| / limit over",
        f"the joints on a dense resampling; 1 is at the limit, and the limits asked are held within {TOLERANCE_PERCENT:g} %.",
        "--json prints every figure and the warnings.",
    ]
    return "\n".join(lines) + "\n"
