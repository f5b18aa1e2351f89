"""Write a raw run in the spec's CSV form: a folder with ``run.json`` and one CSV per topic."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from swtlab_base.atomic import atomic_file, write_atomically
from virtual_testbed.measure import RawRun
from virtual_testbed.topics import TOPIC_FIELDS, csv_name


def write_csv(raw: RawRun, folder: Path) -> Path:
    """Write ``raw`` into ``folder`` (created); same input, same bytes."""
    folder.mkdir(parents=True, exist_ok=True)
    write_atomically(folder / "run.json", json.dumps(raw.metadata, indent=2) + "\n")
    for topic, channel in raw.channels.items():
        table = pd.DataFrame({"t_s": channel["t_ns"] / 1e9,
                              **{f: channel[f] for f in TOPIC_FIELDS[topic]}})
        with atomic_file(folder / csv_name(topic), newline="") as stream:
            table.to_csv(stream, index=False, lineterminator="\n")
    for topic, photos in raw.images.items():
        frames = folder / csv_name(topic).removesuffix(".csv")
        frames.mkdir(exist_ok=True)
        for photo in photos:
            write_atomically(
                frames / f"{photo.t_ns}.{'jpg' if photo.format == 'jpeg' else photo.format}",
                photo.data)
    return folder
