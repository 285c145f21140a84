"""Message-by-message comparison of two MCAP logs (what ``rerun`` checks)."""

from __future__ import annotations

import json
from pathlib import Path

from bioflex_jsb.sinks.mcap.reader import messages_by_topic

ABS_TOL = 1e-12  # absolute tolerance below which two numbers agree [their unit]


def _differs(a, b, rtol: float) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() != b.keys() or any(_differs(a[k], b[k], rtol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) != len(b) or any(_differs(x, y, rtol) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or a is None:
        return a != b
    if isinstance(a, int | float) and isinstance(b, int | float):
        return abs(a - b) > max(ABS_TOL, rtol * max(abs(a), abs(b)))
    return a != b


def compare_logs(old: str | Path, new: str | Path, rtol: float) -> dict:
    """Topics, message counts, log times and every number of two logs; numbers agree within
    ``rtol`` relative [-] or :data:`ABS_TOL` absolute. ``equal`` and the first difference (one
    line). A file that cannot be read is a :class:`LogError`."""
    a, b = messages_by_topic(old), messages_by_topic(new)
    result = {"equal": True, "messages": sum(len(v) for v in a.values()), "topics": len(a),
              "first_difference": None}
    if a.keys() != b.keys():
        result.update(equal=False, first_difference=(
            f"topics differ: {sorted(set(a) ^ set(b))}"))
        return result
    for topic_name in sorted(a):
        ma, mb = a[topic_name], b[topic_name]
        if len(ma) != len(mb):
            result.update(equal=False, first_difference=(
                f"{topic_name}: {len(ma)} messages in the original, {len(mb)} in the rerun"))
            return result
        for (ta, xa), (tb, xb) in zip(ma, mb, strict=True):
            if ta != tb or _differs(xa, xb, rtol):
                result.update(equal=False, first_difference=(
                    f"{topic_name} at t = {ta * 1e-9:.6f} s: {json.dumps(xa)} != "
                    f"{json.dumps(xb)}"))
                return result
    return result
