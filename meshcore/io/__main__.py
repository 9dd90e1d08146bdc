"""``python -m meshcore.io``: print the table of formats."""

from __future__ import annotations

from . import FORMATS


def main() -> int:
    rows = [("format", "suffixes", "write", "read", "CRS", "markers", "blocks", "description")]
    for f in FORMATS.values():
        rows.append(
            (
                f.name,
                " ".join(f.suffixes),
                "yes" if f.writer else "",
                "grid" if f.grid_reader else "points" if f.points_reader else "",
                "yes" if f.crs else "",
                "yes" if f.markers else "",
                "many" if f.multiblock else "one",
                f.description,
            )
        )
    widths = [max(len(r[k]) for r in rows) for k in range(len(rows[0]))]
    for r in rows:
        print("  ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)).rstrip())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
