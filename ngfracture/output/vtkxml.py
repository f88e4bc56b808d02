"""VTK XML files (.vtu unstructured grids, .vtp poly data) written from numpy arrays.

Unstructured grids of triangles (2D meshes) or tetrahedra (3D meshes); poly data of line
segments (2D crack faces) or triangles (3D crack faces).

The format of VTK's own XML writers in appended raw mode: an XML header that describes
every array and gives its byte offset, then ``<AppendedData encoding="raw">`` with the
arrays' bytes (little endian, UInt64 headers). A compressed array is split into blocks of
32 KiB, each compressed on its own; its header lists the number of blocks, the block size,
the size of the last block and every block's compressed size (VTK's
``vtkZLibDataCompressor`` / ``vtkLZMADataCompressor``). String arrays (field data) are
their characters, each string followed by a zero byte.

Written here rather than through VTK's writer: a run's time series then does not import
VTK (0.16 to 0.24 s of a default plate's 3 s) and builds no VTK objects; ParaView, VTK's
reader and PyVista read the files (tests/test_output.py reads every compression back).
"""
import lzma
import zlib

import numpy as np

#: compressions of this module -> the XML ``compressor`` attribute (None: raw bytes)
COMPRESSORS = {None: None, "zlib": "vtkZLibDataCompressor", "lzma": "vtkLZMADataCompressor"}

#: uncompressed bytes per compressed block (VTK's default)
BLOCK_SIZE = 32768

_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32",
          np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32", np.dtype(np.int16): "Int16",
          np.dtype(np.int8): "Int8", np.dtype(np.uint64): "UInt64", np.dtype(np.uint32): "UInt32",
          np.dtype(np.uint16): "UInt16", np.dtype(np.uint8): "UInt8"}

VTK_LINE, VTK_TRIANGLE, VTK_TETRA = 3, 5, 10

#: corners of the cell types of :func:`unstructured_grid`
CORNERS = {VTK_TRIANGLE: 3, VTK_TETRA: 4}


def _compress(raw, compression):
    if compression == "zlib":
        return zlib.compress(raw, 1)
    return lzma.compress(raw, format=lzma.FORMAT_XZ, check=lzma.CHECK_CRC64, preset=1)


def _block(raw, compression):
    """The appended bytes of one array: header and data, compressed in blocks if asked."""
    if compression is None:
        return np.array([len(raw)], dtype="<u8").tobytes() + raw
    if not raw:
        return np.array([0, BLOCK_SIZE, 0], dtype="<u8").tobytes()
    parts = [_compress(raw[i:i + BLOCK_SIZE], compression) for i in range(0, len(raw), BLOCK_SIZE)]
    last = len(raw) % BLOCK_SIZE
    header = np.array([len(parts), BLOCK_SIZE, last] + [len(p) for p in parts], dtype="<u8")
    return header.tobytes() + b"".join(parts)


def _as_array(values):
    """A little-endian array of a VTK type, shape (n,) or (n, components)."""
    v = np.asarray(values)
    if v.dtype == bool:
        v = v.astype(np.uint8)
    if v.dtype.newbyteorder("=") not in _TYPES:
        raise TypeError(f"ngfracture.output.vtkxml: arrays of dtype {v.dtype} have no VTK type")
    v = v.reshape(len(v), -1) if v.ndim > 2 else v
    return np.ascontiguousarray(v, dtype=v.dtype.newbyteorder("<"))


class _Appended:
    """The XML lines and the appended bytes of a file, array by array."""

    def __init__(self, compression):
        self.compression = compression
        self.blocks = []
        self.offset = 0

    def data_array(self, name, values, indent):
        v = _as_array(values)
        components = f' NumberOfComponents="{v.shape[1]}"' if v.ndim == 2 else ""
        line = (f'{indent}<DataArray type="{_TYPES[v.dtype.newbyteorder("=")]}" Name="{_escape(name)}"'
                f'{components} format="appended" offset="{self.offset}"/>')
        self._add(v.tobytes())
        return line

    def string_array(self, name, strings, indent):
        raw = b"".join(s.encode() + b"\0" for s in strings)
        line = (f'{indent}<Array type="String" Name="{_escape(name)}" NumberOfTuples="{len(strings)}" '
                f'format="appended" offset="{self.offset}"/>')
        self._add(raw)
        return line

    def _add(self, raw):
        block = _block(raw, self.compression)
        self.blocks.append(block)
        self.offset += len(block)


def _escape(text):
    text = str(text)
    if any(ord(c) < 32 for c in text):
        raise ValueError(f"ngfracture.output.vtkxml: the name {text!r} has control characters")
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace(">", "&gt;")


def _attributes(tag, arrays, appended, indent, rows):
    """PointData / CellData (``rows`` entries each): the first array is the active scalars
    (ParaView colours by it)."""
    if not arrays:
        return [f"{indent}<{tag}/>"]
    for name, values in arrays.items():
        if len(values) != rows:
            raise ValueError(f"ngfracture.output.vtkxml: {tag} array {name!r} has {len(values)} rows, expected {rows}")
    first = next(iter(arrays))
    lines = [f'{indent}<{tag} Scalars="{_escape(first)}">']
    lines += [appended.data_array(name, values, indent + "  ") for name, values in arrays.items()]
    return lines + [f"{indent}</{tag}>"]


def _file(kind, piece, body, field_strings, appended):
    compressor = COMPRESSORS[appended.compression]
    attr = f' compressor="{compressor}"' if compressor else ""
    lines = ['<?xml version="1.0"?>',
             f'<VTKFile type="{kind}" version="1.0" byte_order="LittleEndian" header_type="UInt64"{attr}>',
             f"  <{kind}>"]
    if field_strings:
        lines.append("    <FieldData>")
        lines += [appended.string_array(name, strings, "      ") for name, strings in field_strings.items()]
        lines.append("    </FieldData>")
    lines += [f"    <Piece {piece}>"] + body + ["    </Piece>", f"  </{kind}>", '  <AppendedData encoding="raw">']
    head = ("\n".join(lines) + "\n   _").encode()
    return head + b"".join(appended.blocks) + b"\n  </AppendedData>\n</VTKFile>\n"


def _check(compression, points, cells, corners):
    if compression not in COMPRESSORS:
        raise ValueError(f"ngfracture.output.vtkxml: compression must be one of {list(COMPRESSORS)}, got {compression!r}")
    p = np.asarray(points)
    c = np.asarray(cells)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"ngfracture.output.vtkxml: points must have shape (n, 2) or (n, 3), got {p.shape}")
    if c.size and (c.ndim != 2 or c.shape[1] != corners):
        raise ValueError(f"ngfracture.output.vtkxml: cells must have shape (m, {corners}), got {c.shape}")
    p3 = np.zeros((len(p), 3))
    p3[:, :p.shape[1]] = p
    return p3, c.reshape(-1, corners).astype(np.int64)


def _data_and_points(appended, point_data, cell_data, points, ncells):
    """The lines of a piece before its cells: point data, cell data, points."""
    return (_attributes("PointData", point_data, appended, "      ", len(points))
            + _attributes("CellData", cell_data, appended, "      ", ncells)
            + ["      <Points>", appended.data_array("Points", points, "        "), "      </Points>"])


def _cell_arrays(appended, cells, indent):
    corners = cells.shape[1]
    offsets = np.arange(corners, corners * len(cells) + 1, corners, dtype=np.int64)
    return [appended.data_array("connectivity", cells.ravel(), indent),
            appended.data_array("offsets", offsets, indent)]


def unstructured_grid(points, cells, point_data=None, cell_data=None, field_strings=None, compression="zlib",
                      cell_type=VTK_TRIANGLE):
    """The bytes of a .vtu file of cells of one type (triangles or tetrahedra).

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        Point coordinates (z = 0 if two columns).
    cells : array_like of int, shape (m, 3) or (m, 4)
        0-based point numbers, as many columns as ``cell_type`` has corners.
    point_data, cell_data : dict of str -> array_like, optional
        Arrays with one row per point / cell (1 or 2 dimensions; bool as UInt8). The
        first of each is the active scalars.
    field_strings : dict of str -> list of str, optional
        String arrays of the field data.
    compression : {'zlib', 'lzma', None}
    cell_type : {VTK_TRIANGLE, VTK_TETRA}
        VTK cell type of every cell (5 or 10).

    Returns
    -------
    bytes

    Raises
    ------
    ValueError
        Unknown compression or cell type, points / cells of the wrong shape, an array
        without one row per point / cell, a name with control characters.
    TypeError
        An array of a dtype VTK has no type for.
    """
    if cell_type not in CORNERS:
        raise ValueError(f"ngfracture.output.vtkxml: cell_type must be one of {list(CORNERS)}, got {cell_type!r}")
    p, t = _check(compression, points, cells, CORNERS[cell_type])
    appended = _Appended(compression)
    body = (_data_and_points(appended, point_data, cell_data, p, len(t))
            + ["      <Cells>"] + _cell_arrays(appended, t, "        ")
            + [appended.data_array("types", np.full(len(t), cell_type, dtype=np.uint8), "        "),
               "      </Cells>"])
    return _file("UnstructuredGrid", f'NumberOfPoints="{len(p)}" NumberOfCells="{len(t)}"', body,
                 field_strings, appended)


def poly_lines(points, lines, point_data=None, compression="zlib"):
    """The bytes of a .vtp file of line segments.

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
    lines : array_like of int, shape (m, 2)
        0-based point numbers.
    point_data : dict of str -> array_like, optional
        As for :func:`unstructured_grid`.
    compression : {'zlib', 'lzma', None}

    Returns
    -------
    bytes

    Raises
    ------
    ValueError, TypeError
        As :func:`unstructured_grid`.
    """
    return _poly(points, lines, point_data, compression, "Lines")


def poly_triangles(points, triangles, point_data=None, compression="zlib"):
    """The bytes of a .vtp file of triangles (polygons of three corners).

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
    triangles : array_like of int, shape (m, 3)
        0-based point numbers.
    point_data : dict of str -> array_like, optional
        As for :func:`unstructured_grid`.
    compression : {'zlib', 'lzma', None}

    Returns
    -------
    bytes

    Raises
    ------
    ValueError, TypeError
        As :func:`unstructured_grid`.
    """
    return _poly(points, triangles, point_data, compression, "Polys")


def _poly(points, cells, point_data, compression, kind):
    """A .vtp of one kind of cells: ``Lines`` (2 corners) or ``Polys`` (triangles)."""
    p, s = _check(compression, points, cells, 2 if kind == "Lines" else 3)
    appended = _Appended(compression)
    body = (_data_and_points(appended, point_data, {}, p, len(s))
            + [f"      <{kind}>"] + _cell_arrays(appended, s, "        ") + [f"      </{kind}>"])
    counts = {"Lines": 0, "Polys": 0}
    counts[kind] = len(s)
    piece = (f'NumberOfPoints="{len(p)}" NumberOfVerts="0" NumberOfLines="{counts["Lines"]}" '
             f'NumberOfStrips="0" NumberOfPolys="{counts["Polys"]}"')
    return _file("PolyData", piece, body, None, appended)
