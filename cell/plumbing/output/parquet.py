"""``--format parquet``: a result file as Apache Parquet, with the columns, types and
values that reading its CSV gives (:func:`pandas.read_csv`), so the two read back equal.

The CSV stays the one way results are made (streamed rows, fixed float format, the
byte-identical reruns the tests check); the Parquet file is that CSV read and written
once more with pyarrow, so it holds the same rounded values, never others.  A sweep's
``replications.parquet`` is written so from the CSV text in memory, in place of
``replications.csv``.
"""

from __future__ import annotations

import os

#: The formats ``cell run`` and ``cell sweep`` write.
FORMATS = ("csv", "parquet")


def parquet_name(name: str) -> str:
    """``parts.csv`` → ``parts.parquet``."""
    return name.removesuffix(".csv") + ".parquet"


def csv_to_parquet(csv_path: str | os.PathLike[str], parquet_path: str | os.PathLike[str]) -> None:
    """Write the CSV file ``csv_path`` as Parquet at ``parquet_path`` (pyarrow, no index)."""
    import pandas as pd

    frame = pd.read_csv(csv_path)
    frame.to_parquet(parquet_path, engine="pyarrow", index=False)


def csv_text_to_parquet(text: str, parquet_path: str | os.PathLike[str]) -> None:
    """A CSV file's ``text`` as Parquet at ``parquet_path``, as :func:`csv_to_parquet` writes
    that file: the values and types :func:`pandas.read_csv` gives it."""
    import io

    import pandas as pd

    frame = pd.read_csv(io.StringIO(text))
    frame.to_parquet(parquet_path, engine="pyarrow", index=False)
