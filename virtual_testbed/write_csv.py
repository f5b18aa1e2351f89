"""Write a raw run in the spec's CSV form: a folder with ``run.json`` and one CSV per topic."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from virtual_testbed.measure import RawRun
from virtual_testbed.topics import TOPIC_FIELDS, csv_name


def write_csv(raw: RawRun, folder: Path) -> Path:
    """Write ``raw`` into ``folder`` (created); same input, same bytes."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "run.json").write_text(json.dumps(raw.metadata, indent=2) + "\n")
    for topic, channel in raw.channels.items():
        table = pd.DataFrame({"t_s": channel["t_ns"] / 1e9,
                              **{f: channel[f] for f in TOPIC_FIELDS[topic]}})
        table.to_csv(folder / csv_name(topic), index=False, lineterminator="\n")
    for topic, photos in raw.images.items():
        frames = folder / csv_name(topic).removesuffix(".csv")
        frames.mkdir(exist_ok=True)
        for photo in photos:
            (frames / f"{photo.t_ns}.{'jpg' if photo.format == 'jpeg' else photo.format}"
             ).write_bytes(photo.data)
    return folder
