"""A study's table on disk: CSV, or Parquet (pyarrow) by the name's suffix."""
from __future__ import annotations

#: Suffixes :func:`write_table` writes.
TABLE_SUFFIXES = (".csv", ".parquet")


def write_table(frame, path) -> None:
    """Write the table (a DataFrame of :func:`foldcore.study.sweep`) to ``path``
    atomically: ``.csv`` (floats as their shortest exact repr, NaN as an empty cell) or ``.parquet``."""
    import os

    from ..files import atomic_write
    from .points import StudyError

    name = os.fspath(path)
    suffix = os.path.splitext(name)[1].lower()
    if suffix not in TABLE_SUFFIXES:
        raise StudyError(f"{name}: a table is written as {' or '.join(TABLE_SUFFIXES)}")
    if suffix == ".parquet":
        import importlib.util

        if importlib.util.find_spec("pyarrow") is None:
            raise StudyError(f"{name}: Parquet needs pyarrow (pip install pyarrow)")
        with atomic_write(name, binary=True) as fh:
            frame.to_parquet(fh, index=False)
        return
    with atomic_write(name) as fh:
        frame.to_csv(fh, index=False)
