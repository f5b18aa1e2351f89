"""Reader for a lab's delimited text files (headerless or not) through a channel map."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ingest.channel_map import ChannelMap
from ingest.checks import numeric_column
from ingest.cut_short import CUT_LINE, last_line_cut
from ingest.errors import IngestError
from ingest.raw import RawRun, RawTopic


def read_delimited(path: Path, cmap: ChannelMap) -> RawRun:
    """One run in one delimited file; columns named by the map's column order."""
    path = Path(path)
    try:
        frame = pd.read_csv(path, sep=cmap.delimiter, header=None, skiprows=cmap.header_rows,
                            comment=cmap.comment, engine="c",
                            skipinitialspace=True)
    except pd.errors.EmptyDataError:
        raise IngestError(path, None, "empty file") from None
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise IngestError(path, None, f"cannot parse as delimited text: {exc}") from None
    cut = last_line_cut(path)
    if cut:
        frame = frame.iloc[:-1]  # a row the logger did not finish (ingest.cut_short)
    if frame.shape[1] != len(cmap.columns):
        raise IngestError(path, None, f"{frame.shape[1]} columns, the channel map "
                          f"{cmap.path.name} expects {len(cmap.columns)} "
                          f"({', '.join(cmap.columns)})")
    frame.columns = list(cmap.columns)
    wanted = {cmap.time_column} | {c.field for c in cmap.channels}
    fields = {}
    for name in cmap.columns:
        if name not in wanted:
            continue
        fields[name] = numeric_column(path, frame, name, first_row=1 + cmap.header_rows)
    t = fields.pop(cmap.time_column)
    t_s = (t - t[0]) * cmap.time_scale_s if len(t) else t
    return RawRun(path=path, records={}, topics={cmap.stream: RawTopic(t_s=t_s, fields=fields)},
                  cut_short=CUT_LINE if cut else None)
