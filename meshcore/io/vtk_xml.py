r"""VTK XML StructuredGrid (``.vts``) and MultiBlock (``.vtm``) files.

Written as raw appended binary (``header_type="UInt64"``, little endian,
float64), readable by VTK/ParaView.  Contents of each ``.vts``:

* ``Points`` — world coordinates ``(x + x0, y + y0, 0)``, i fastest;
* ``PointData`` — the node metrics of :func:`meshcore.metrics.metrics`
  (``jacobian`` = x_ξ y_η − x_η y_ξ, ``x_xi`` … ``eta_y``, ``alpha``,
  ``beta``, ``gamma``);
* ``CellData`` — :func:`meshcore.quality.cell_quality` (``area``,
  ``jacobian_ratio``, ``orthogonality``, ``skewness``, ``aspect_ratio``,
  ``size_ratio``; ``min_corner_jacobian``);
* ``FieldData`` — ``crs`` (authority string or WKT), ``origin`` (x0, y0) and
  ``border_names`` (JSON: ``{"bottom": "inlet", "right": "right", …}``); a
  block of a ``.vtm`` also ``write_id`` and ``connectivity`` (JSON list of
  ``[a, border_a, b, border_b, reversed, range_a, range_b]``).

A ``.vtm`` lists one ``.vts`` per block, stored in a directory named after the
``.vtm`` stem next to it.  The reader accepts ASCII, inline base64 and
appended (raw or base64) data, UInt32/UInt64 headers and zlib compression.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import struct
import tempfile
import uuid
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from ..crs import Frame
from ..errors import ReadError, WriteError
from ..grid import BORDER_NAMES, StructuredGrid
from ._base import (
    GridSet,
    Interface,
    atomic_path,
    border_names,
    check_interface,
    check_nodes,
    clean_stale_temporaries,
    grid_from_world,
    one_line,
    parse_xml,
    read_bytes,
    temp_prefix,
)

__all__ = ["read_vtm", "read_vts", "write_vtm", "write_vts"]


def _string_array(name: str, s: str) -> str:
    codes = " ".join(str(b) for b in s.encode("utf-8")) + " 0"
    return (
        f'      <Array type="String" Name="{name}" NumberOfTuples="1" format="ascii">\n'
        f"        {codes}\n      </Array>\n"
    )


def _vts_bytes(g: StructuredGrid, frame: Frame, *, data: bool = True, extra: dict[str, str] | None = None) -> bytes:
    from ..metrics import metrics
    from ..quality import cell_quality

    ni, nj = g.cells
    X, Y = frame.to_world(g.x, g.y)
    pts = np.column_stack([X.ravel(order="F"), Y.ravel(order="F"), np.zeros(X.size)])
    arrays: list[tuple[str, str, int, np.ndarray]] = []  # (section, name, ncomp, values)
    arrays.append(("Points", "Points", 3, pts))
    if data:
        m = metrics(g).as_dict()
        for k, v in m.items():
            arrays.append(("PointData", k, 1, v.ravel(order="F")))
        cq = cell_quality(g)
        for k, v in cq.items():
            if k == "corner_jacobians":
                arrays.append(("CellData", "min_corner_jacobian", 1, v.min(axis=0).ravel(order="F")))
            else:
                arrays.append(("CellData", k, 1, v.ravel(order="F")))
    blobs = []
    offset = 0
    xml: dict[str, list[str]] = {"Points": [], "PointData": [], "CellData": []}
    for section, name, nc, v in arrays:
        raw = np.ascontiguousarray(v, dtype="<f8").tobytes()
        blobs.append(struct.pack("<Q", len(raw)) + raw)
        xml[section].append(
            f'        <DataArray type="Float64" Name="{name}" NumberOfComponents="{nc}" '
            f'format="appended" offset="{offset}"/>\n'
        )
        offset += 8 + len(raw)
    names = border_names(g)
    field = (
        "    <FieldData>\n"
        + (_string_array("crs", frame.crs) if frame.crs else "")
        + '      <Array type="Float64" Name="origin" NumberOfTuples="1" NumberOfComponents="2" '
        f'format="ascii">{frame.origin[0]!r} {frame.origin[1]!r}</Array>\n'
        + _string_array("border_names", json.dumps({b: names[b] for b in BORDER_NAMES}))
        + "".join(_string_array(k, v) for k, v in (extra or {}).items())
        + "    </FieldData>\n"
    )
    ext = f"0 {ni} 0 {nj} 0 0"
    head = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n'
        f'  <StructuredGrid WholeExtent="{ext}">\n' + field + f'    <Piece Extent="{ext}">\n'
        "      <PointData>\n" + "".join(xml["PointData"]) + "      </PointData>\n"
        "      <CellData>\n" + "".join(xml["CellData"]) + "      </CellData>\n"
        "      <Points>\n" + "".join(xml["Points"]) + "      </Points>\n"
        "    </Piece>\n  </StructuredGrid>\n"
        '  <AppendedData encoding="raw">\n   _'
    )
    return head.encode("utf-8") + b"".join(blobs) + b"\n  </AppendedData>\n</VTKFile>\n"


def write_vts(path: Path, gs: GridSet, *, data: bool = True, **_: Any) -> None:
    """Write a single block as ``.vts`` (see module docstring)."""
    if len(gs.blocks) != 1:
        raise WriteError(f"{path}: .vts holds one block, got {len(gs.blocks)}; write a .vtm")
    blob = _vts_bytes(gs.blocks[0], gs.frame, data=data)
    with atomic_path(path) as tmp:
        tmp.write_bytes(blob)


def _connectivity_json(gs: GridSet) -> str:
    return json.dumps(
        [[it.a, it.border_a, it.b, it.border_b, it.reversed, it.range_a, it.range_b] for it in gs.connectivity]
    )


def write_vtm(path: Path, gs: GridSet, *, data: bool = True, **_: Any) -> None:
    """Write blocks as a ``.vtm`` plus a directory (named after its stem) of ``.vts`` files.

    Every ``.vts`` holds the block connectivity (``connectivity``, JSON) and
    the id of this write (``write_id``), which the ``.vtm`` holds too: a
    ``.vtm`` and a block folder from two different writes (a crash between
    the two renames that replace them) are refused by :func:`read_vtm`
    instead of read.  The new folder is complete before either rename.
    """
    path = Path(path)
    sub = path.with_suffix("")
    parent = path.parent if str(path.parent) else Path(".")
    write_id = uuid.uuid4().hex
    check_block_folder(path, sub)
    clean_stale_temporaries(path)
    try:
        tmpdir = Path(tempfile.mkdtemp(prefix=temp_prefix(path), suffix=".tmpdir", dir=parent))
    except OSError as exc:
        raise WriteError(one_line(f"{path}: cannot write here ({exc.strerror or exc})")) from None
    old = None
    try:
        entries = []
        extra = {"write_id": write_id, "connectivity": _connectivity_json(gs)}
        for k, g in enumerate(gs.blocks):
            fn = f"{sub.name}_{k}.vts"
            (tmpdir / fn).write_bytes(_vts_bytes(g, gs.frame, data=data, extra=extra))
            entries.append(f'    <DataSet index="{k}" name="{_xml_attr(gs.block_names[k])}" file="{sub.name}/{fn}"/>\n')
        vtm = (
            '<?xml version="1.0"?>\n'
            '<VTKFile type="vtkMultiBlockDataSet" version="1.0" byte_order="LittleEndian" '
            f'header_type="UInt64" meshcore_write_id="{write_id}">\n  <vtkMultiBlockDataSet>\n'
            + "".join(entries)
            + "  </vtkMultiBlockDataSet>\n</VTKFile>\n"
        )
        os.chmod(tmpdir, 0o755)
        with atomic_path(path) as tmp:
            tmp.write_text(vtm, encoding="utf-8")
            if sub.exists():
                old = Path(tempfile.mkdtemp(prefix=temp_prefix(path), suffix=".tmpdir", dir=parent))
                os.replace(sub, old / "d")
            os.replace(tmpdir, sub)
    except BaseException as exc:
        shutil.rmtree(tmpdir, ignore_errors=True)
        if old is not None and (old / "d").exists() and not sub.exists():
            os.replace(old / "d", sub)
        if isinstance(exc, OSError) and not isinstance(exc, WriteError):
            raise WriteError(one_line(f"{path}: cannot write ({exc.strerror or exc})")) from exc
        raise
    finally:
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def check_block_folder(path: Path, sub: Path) -> None:
    """Refuse to write ``path`` when ``sub`` (the folder its blocks go to, replaced whole) is
    anything but an earlier write's block folder: a file, a link, or a folder holding any other
    file (``meshcore mesh lake/outline.kml -o lake.vtm`` deleted the folder of its own input)."""
    import re

    if not (sub.exists() or sub.is_symlink()):
        return
    if sub.is_symlink() or not sub.is_dir():
        raise WriteError(
            one_line(f"{path}: its block folder {sub} would replace a file of that name; write to another name")
        )
    ours = re.compile(rf"{re.escape(sub.name)}_\d+\.vts")
    try:
        others = sorted(
            e.name for e in os.scandir(sub) if not (ours.fullmatch(e.name) and e.is_file(follow_symlinks=False))
        )
    except OSError as exc:
        raise WriteError(one_line(f"{path}: cannot read its block folder {sub} ({exc.strerror or exc})")) from None
    if others:
        listed = ", ".join(others[:3]) + (f" and {len(others) - 3} more" if len(others) > 3 else "")
        raise WriteError(
            one_line(
                f"{path}: its block folder {sub} holds files that are not its blocks ({listed}); "
                "the folder is replaced whole by a write, so nothing was written: write to another name"
            )
        )


def _xml_attr(s: str) -> str:
    return s.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace(">", "&gt;")


# ----------------------------------------------------------------- reading
_DTYPES = {
    "Float64": "f8",
    "Float32": "f4",
    "Int8": "i1",
    "UInt8": "u1",
    "Int16": "i2",
    "UInt16": "u2",
    "Int32": "i4",
    "UInt32": "u4",
    "Int64": "i8",
    "UInt64": "u8",
    "String": "u1",
    "Char": "i1",
}


def _parse(data: bytes, path: Path):
    # cut the raw appended section before XML parsing
    marker = data.find(b"<AppendedData")
    appended = b""
    if marker >= 0:
        start = data.find(b">", marker)
        us = data.find(b"_", start)
        end = data.rfind(b"</AppendedData>")
        if start < 0 or us < 0 or end < us:
            raise ReadError(f"{path}: malformed <AppendedData> section")
        appended = data[us + 1 : end]
        data = data[: start + 1] + b"</AppendedData>" + data[end + len(b"</AppendedData>") :]
    root = parse_xml(data, str(path), kind="VTK")
    return root, appended


class _Decoder:
    def __init__(self, root, appended: bytes, path: Path):
        self.path = path
        bo = root.get("byte_order", "LittleEndian")
        self.bo = "<" if bo == "LittleEndian" else ">"
        self.header = np.dtype(self.bo + ("u8" if root.get("header_type") == "UInt64" else "u4"))
        self.compressed = root.get("compressor") == "vtkZLibDataCompressor"
        app = None
        for e in root.iter():
            if e.tag.rsplit("}", 1)[-1] == "AppendedData":
                app = e
        self.app_encoding = app.get("encoding", "raw") if app is not None else "raw"
        if self.app_encoding == "base64":
            self.appended = appended.strip()
        else:
            # the appended data may end with white space before </AppendedData>
            self.appended = appended

    def _unpack(self, buf: bytes, b64: bool, limit: int) -> bytes:
        """The bytes of one array (at most ``limit``: checked from the headers before inflating)."""
        hs = self.header.itemsize

        def chars(nbytes: int) -> int:
            return ((nbytes + 2) // 3) * 4

        if b64:
            buf = buf.lstrip()
            first = base64.b64decode(buf[: chars(hs)])
            if len(first) < hs:
                raise ReadError(f"{self.path}: base64 data truncated")
            n0 = int(np.frombuffer(first[:hs], dtype=self.header)[0])
            if not self.compressed:
                self._check_size(n0, limit)
                # VTK encodes the header and the data separately; accept both ways
                data = base64.b64decode(buf[chars(hs) : chars(hs) + chars(n0)])
                if len(data) >= n0:
                    return data[:n0]
                whole = base64.b64decode(buf[: chars(hs + n0)])
                if len(whole) < hs + n0:
                    raise ReadError(f"{self.path}: base64 data truncated")
                return whole[hs : hs + n0]
            if n0 > len(buf):  # more blocks than characters: a corrupt header
                raise ReadError(f"{self.path}: compressed array header claims {n0} blocks")
            hlen = (3 + n0) * hs
            hdr = np.frombuffer(base64.b64decode(buf[: chars(hlen)])[:hlen], dtype=self.header)
            if len(hdr) < 3 + n0:
                raise ReadError(f"{self.path}: compressed array header truncated")
            total = int(hdr[3 : 3 + n0].astype(np.int64).sum())
            if total > len(buf):
                raise ReadError(f"{self.path}: compressed array larger than the file")
            body = base64.b64decode(buf[chars(hlen) : chars(hlen) + chars(total)])
            return self._inflate(hdr, body, limit)
        if len(buf) < hs:
            raise ReadError(f"{self.path}: appended data truncated")
        n0 = int(np.frombuffer(buf[:hs], dtype=self.header)[0])
        if not self.compressed:
            if len(buf) < hs + n0:
                raise ReadError(f"{self.path}: appended data truncated")
            self._check_size(n0, limit)
            return buf[hs : hs + n0]
        if n0 > len(buf):
            raise ReadError(f"{self.path}: compressed array header claims {n0} blocks")
        hdr = np.frombuffer(buf[: (3 + n0) * hs], dtype=self.header)
        if len(hdr) < 3 + n0:
            raise ReadError(f"{self.path}: compressed array header truncated")
        return self._inflate(hdr, buf[(3 + n0) * hs :], limit)

    def _check_size(self, nbytes: int, limit: int) -> None:
        if nbytes > limit:
            raise ReadError(
                f"{self.path}: refused: an array would inflate to {nbytes:,} bytes, more than the "
                f"{limit:,} its grid size allows"
            )

    def _inflate(self, hdr: np.ndarray, body: bytes, limit: int) -> bytes:
        """zlib blocks of a VTK compressed array; sizes from the header, each block capped while inflating."""
        nb, block, last = int(hdr[0]), int(hdr[1]), int(hdr[2])
        if nb == 0:
            return b""
        full = (nb - 1) * block + (last if last else block)
        self._check_size(full, limit)
        sizes = hdr[3 : 3 + nb].astype(np.int64)
        out, pos = [], 0
        for k, s in enumerate(sizes):
            want = block if (k < nb - 1 or not last) else last
            d = zlib.decompressobj()
            chunk = d.decompress(body[pos : pos + int(s)], want)
            if d.unconsumed_tail or len(chunk) != want:
                raise ReadError(f"{self.path}: compressed block {k} does not inflate to its declared {want} bytes")
            out.append(chunk)
            pos += int(s)
        return b"".join(out)

    def array(self, e, limit: int) -> np.ndarray:
        """The values of a DataArray as float64 (at most ``limit`` bytes of raw data)."""
        typ = e.get("type", "Float64")
        if typ not in _DTYPES:
            raise ReadError(f"{self.path}: DataArray {e.get('Name')!r} has unknown type {typ!r}")
        dt = np.dtype(self.bo + _DTYPES[typ])
        fmt = e.get("format", "ascii")
        if fmt == "ascii":
            return np.array((e.text or "").split(), dtype=np.float64)
        if fmt == "binary":
            raw = self._unpack((e.text or "").encode("ascii"), True, limit)
        elif fmt == "appended":
            try:
                off = int(e.get("offset", "0"))
            except ValueError:
                raise ReadError(f"{self.path}: DataArray offset {e.get('offset')[:20]!r} is not an integer") from None
            if not 0 <= off < len(self.appended):
                raise ReadError(f"{self.path}: DataArray offset {off} is outside the appended data")
            raw = self._unpack(self.appended[off:], self.app_encoding == "base64", limit)
        else:
            raise ReadError(f"{self.path}: unknown DataArray format {fmt[:20]!r}")
        return np.frombuffer(raw[: len(raw) // dt.itemsize * dt.itemsize], dtype=dt).astype(np.float64)


#: Largest string array (CRS WKT, border names) read from a .vts.
_STRING_LIMIT = 2**20


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _read_vts(path: Path) -> tuple[StructuredGrid, Frame, dict[str, str]]:
    """The grid, frame and meshcore string fields (``write_id``, ``connectivity``) of a ``.vts``."""
    root, appended = _parse(read_bytes(path), path)
    if _local(root.tag) != "VTKFile" or root.get("type") != "StructuredGrid":
        raise ReadError(f"{path}: not a VTK StructuredGrid file")
    dec = _Decoder(root, appended, path)
    sg = next((e for e in root.iter() if _local(e.tag) == "StructuredGrid"), None)
    piece = next((e for e in root.iter() if _local(e.tag) == "Piece"), None)
    if sg is None or piece is None:
        raise ReadError(f"{path}: no <StructuredGrid>/<Piece>")
    try:
        ext = [int(v) for v in (piece.get("Extent") or sg.get("WholeExtent") or "").split()]
    except ValueError:
        raise ReadError(f"{path}: Extent is not 6 integers") from None
    if len(ext) != 6:
        raise ReadError(f"{path}: Extent is not 6 integers")
    ni, nj, nk = ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1
    if nk != 1 or ni < 2 or nj < 2:
        raise ReadError(f"{path}: extent {ext} is not a 2-D grid of at least 2 × 2 nodes")
    check_nodes((ni, nj), path)
    pts_el = next((e for e in piece.iter() if _local(e.tag) == "Points"), None)
    arr_el = None if pts_el is None else next((e for e in pts_el if _local(e.tag) == "DataArray"), None)
    if arr_el is None:
        raise ReadError(f"{path}: no <Points> DataArray")
    p = dec.array(arr_el, 3 * ni * nj * 8)
    if p.size != 3 * ni * nj:
        raise ReadError(f"{path}: Points has {p.size} values, expected {3 * ni * nj}")
    p = p.reshape(-1, 3)
    X = p[:, 0].reshape((ni, nj), order="F")
    Y = p[:, 1].reshape((ni, nj), order="F")
    crs, origin, names = None, (0.0, 0.0), {}
    fields: dict[str, str] = {}
    for e in root.iter():
        if _local(e.tag) != "Array" and _local(e.tag) != "DataArray":
            continue
        parent_is_field = False
        name = e.get("Name")
        if name == "crs" and e.get("type") == "String":
            crs = _decode_string(e, dec)
            parent_is_field = True
        elif name == "origin" and e.get("format", "ascii") == "ascii":
            try:
                o = [float(v) for v in (e.text or "").split()[:2]]
            except ValueError:
                raise ReadError(f"{path}: the origin field {(e.text or '').strip()[:40]!r} is not numbers") from None
            if len(o) >= 2:
                origin = (o[0], o[1])
        elif name == "border_names" and e.get("type") == "String":
            names = _border_names(_decode_string(e, dec))
        elif name in ("write_id", "connectivity") and e.get("type") == "String":
            fields[name] = _decode_string(e, dec)
        del parent_is_field
    return grid_from_world(X, Y, origin, path, names=names), Frame(crs, origin), fields


def read_vts(path: Path, **_: Any) -> GridSet:
    """Read a ``.vts`` file (2-D: one k layer) with its CRS, origin and border names."""
    g, frame, _fields = _read_vts(path)
    return GridSet((g,), frame, source=str(path))


def _border_names(s: str) -> dict[str, str]:
    """``{"bottom": "inlet", …}`` (JSON) or the older ``bottom=inlet;right=right;…``; defaults dropped."""
    items: dict[str, Any] = {}
    if s.lstrip().startswith("{"):
        try:
            v = json.loads(s)
        except (json.JSONDecodeError, RecursionError):
            v = None
        items = v if isinstance(v, dict) else {}
    else:
        items = dict(item.split("=", 1) for item in s.split(";") if "=" in item)
    return {b: str(n) for b, n in items.items() if b in BORDER_NAMES and str(n) != b}


def _decode_string(e, dec: _Decoder) -> str:
    if e.get("format", "ascii") == "ascii":
        try:
            codes = [int(v) for v in (e.text or "").split()[:_STRING_LIMIT]]
        except ValueError:
            raise ReadError(f"{dec.path}: string array {e.get('Name')!r} holds a non-integer code") from None
    else:
        codes = [int(v) for v in dec.array(e, _STRING_LIMIT)]
    return bytes(c for c in codes if 0 < c < 256).decode("utf-8", errors="replace")


def read_vtm(path: Path, **_: Any) -> GridSet:
    """Read a ``.vtm`` whose blocks are ``.vts`` files.

    Checks that the blocks come from the same write as the ``.vtm`` (when it
    says so) and that the nodes of every stored interface coincide (the
    shared-node check).
    """
    root = parse_xml(read_bytes(path), str(path), kind="VTK")
    if _local(root.tag) != "VTKFile" or root.get("type") != "vtkMultiBlockDataSet":
        raise ReadError(f"{path}: not a VTK MultiBlock file")
    write_id = root.get("meshcore_write_id")
    blocks, names, frame, conn = [], [], None, None
    for e in root.iter():
        if _local(e.tag) != "DataSet":
            continue
        fn = e.get("file")
        if not fn:
            continue
        sub = (path.parent / fn).resolve()
        if not str(sub).endswith(".vts"):
            raise ReadError(f"{path}: block file {fn[:60]!r} is not a .vts")
        if not sub.is_file():
            raise ReadError(f"{path}: block file {fn[:60]!r} not found")
        g, f, fields = _read_vts(sub)
        if write_id is not None and fields.get("write_id") != write_id:
            raise ReadError(
                f"{path}: block file {fn[:60]!r} does not belong to this .vtm (written by another run: "
                f"an interrupted write?); write the grid again"
            )
        blocks.append(g)
        names.append(e.get("name") or f"block{len(names) + 1}")
        frame = frame or f
        conn = conn if conn is not None else fields.get("connectivity")
    if not blocks:
        raise ReadError(f"{path}: no .vts blocks listed")
    interfaces = _interfaces(path, conn, blocks)
    return GridSet(tuple(blocks), frame, tuple(names), interfaces, source=str(path))


def _interfaces(path: Path, text: str | None, blocks: list[StructuredGrid]) -> tuple[Interface, ...]:
    if not text:
        return ()
    try:
        recs = json.loads(text)
        out = tuple(
            Interface(int(a), str(ba), int(b), str(bb), bool(r), _pair(ra), _pair(rb))
            for a, ba, b, bb, r, ra, rb in recs
        )
    except (json.JSONDecodeError, RecursionError, TypeError, ValueError):
        raise ReadError(f"{path}: the connectivity field is not a list of interfaces") from None
    for k, it in enumerate(out):
        if not (0 <= it.a < len(blocks) and 0 <= it.b < len(blocks)) or {it.border_a, it.border_b} - set(BORDER_NAMES):
            raise ReadError(f"{path}: interface {k} names an unknown block or border")
        check_interface(it, blocks, f"{path}: interface {k}", ReadError)
    return out


def _pair(v: Any) -> tuple[int, int] | None:
    return None if v is None else (int(v[0]), int(v[1]))
