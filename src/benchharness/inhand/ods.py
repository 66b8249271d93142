"""Read the cells of an OpenDocument spreadsheet as text.

The published in-hand data are ``.ods`` files whose cells hold comma-separated
numbers as *strings*, so the displayed text is what we want, not the typed
value. ODF compresses runs of equal cells with ``number-columns-repeated``
(the YuMi sheet stores two equal contact cells that way), and pads sheets with
huge repeated empty rows/columns; both are expanded here, the padding trimmed.
"""

from __future__ import annotations

from pathlib import Path

from odf import teletype
from odf.namespaces import TABLENS
from odf.opendocument import load
from odf.table import Table, TableRow

__all__ = ["read_ods"]

_COL_REPEAT = (TABLENS, "number-columns-repeated")
_ROW_REPEAT = (TABLENS, "number-rows-repeated")
_CELL_NAMES = {"table-cell", "covered-table-cell"}
#: Repeats beyond this are padding (LibreOffice writes 1024 columns / 1M rows).
_MAX_REAL_REPEAT = 1000


def _row_cells(row) -> list[str]:
    cells: list[str] = []
    for node in row.childNodes:
        if getattr(node, "qname", (None, None))[1] not in _CELL_NAMES:
            continue
        text = teletype.extractText(node)
        repeat = int(node.attributes.get(_COL_REPEAT, 1) or 1)
        if repeat > _MAX_REAL_REPEAT and not text.strip():
            continue  # trailing padding
        cells.extend([text] * repeat)
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def read_ods(path: str | Path) -> dict[str, list[list[str]]]:
    """Return ``{sheet name: rows}``, each row a list of cell texts.

    Empty rows are dropped and trailing empty cells trimmed, so a row's length
    is the number of its last non-empty column.
    """
    doc = load(str(path))
    sheets: dict[str, list[list[str]]] = {}
    for table in doc.spreadsheet.getElementsByType(Table):
        rows: list[list[str]] = []
        for row in table.getElementsByType(TableRow):
            cells = _row_cells(row)
            if not cells:
                continue
            repeat = int(row.attributes.get(_ROW_REPEAT, 1) or 1)
            rows.extend([list(cells) for _ in range(min(repeat, _MAX_REAL_REPEAT))])
        sheets[str(table.getAttribute("name"))] = rows
    return sheets
