"""Text tables the user gives (CSV): UTF-8, with or without the byte-order mark Excel writes.

Excel's "CSV UTF-8" starts the file with a byte-order mark (BOM, EF BB BF); it is dropped
(encoding ``utf-8-sig``). A file in a legacy code page (Excel's plain "CSV" on Windows writes
cp1252) is refused with one message naming the file and the line, and saying to save it as
UTF-8: its bytes 0x80-0xff mean different letters in each code page (cp1250, cp1251,
cp1252, Mac Roman), so decoding it by guess could silently rename gauges or land-cover
classes.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from floodsph.errors import InputError

UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
"""Byte-order marks of UTF-16 (Excel's "Unicode Text"), little- and big-endian."""


def read_text(path, where: str) -> str:
    """The contents of a UTF-8 text file, a leading BOM dropped.

    ``where`` starts every message (``"gauge file gauges.csv"``, ``"inflows[0].hydrograph:
    q.csv"``). Raises InputError when the file cannot be read or is not UTF-8.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise InputError(f"{where}: cannot be read ({exc.strerror})") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        guess = "a UTF-16 file" if data[:2] in UTF16_BOMS else "perhaps Windows-1252"
        raise InputError(
            f"{where}, line {line}: not UTF-8 text (byte 0x{data[exc.start]:02x}, {guess}); "
            "save the file as UTF-8 (in Excel: \"CSV UTF-8\")"
        ) from None


def read_csv_rows(path, where: str) -> list[list[str]]:
    """The rows of a UTF-8 CSV file (:func:`read_text`), as lists of cell strings."""
    try:
        return list(csv.reader(io.StringIO(read_text(path, where), newline="")))
    except csv.Error as exc:
        raise InputError(f"{where}: cannot be read as CSV ({exc})") from None


#: Separators other than the comma that spreadsheets write (a ';' where the decimal mark is a
#: comma, as in most of Europe), and their names for messages.
OTHER_SEPARATORS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}


def header_found(text: str) -> str:
    """What the first line of a CSV text holds, for the message of a missing column:
    ``found the columns 'id', 'east', 'north'``, or, when the line is one column split by
    another separator, ``found one column 'id;x;y': the file is separated by semicolons;
    save it comma-separated``."""
    first = next(iter(text.splitlines()), "")
    if not first.strip():
        return "found an empty first line"
    columns = next(csv.reader([first]))
    if len(columns) == 1:
        for sep, name in OTHER_SEPARATORS.items():
            if sep in first:
                return (f"found one column {first!r}: the file is separated by {name}; save "
                        "it comma-separated (in Excel: \"CSV UTF-8 (Comma delimited)\")")
    return "found the columns " + ", ".join(repr(c) for c in columns)
