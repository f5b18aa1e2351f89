"""A campaign: a folder of runs at any depth; reading it never stops on one bad run."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ingest.channel_map import ChannelMap, load_channel_map
from ingest.errors import IngestError
from ingest.formats import BY_SUFFIX, ROS2_METADATA
from ingest.run import Run, read_run
from ingest.structured import SIDECAR_SUFFIX


#: run files found by extension (each is then read by its content, ingest.formats.sniff)
RUN_SUFFIXES = tuple(BY_SUFFIX)


@dataclass(frozen=True)
class CampaignRead:
    """Runs that ingested, and one IngestError per run that did not."""

    root: Path
    runs: list[Run] = field(default_factory=list)
    failures: list[IngestError] = field(default_factory=list)


def find_runs(root: str | Path, channel_map: "str | Path | ChannelMap | None" = None) -> list[Path]:
    """Run files/folders under ``root`` (sorted): files with a RUN_SUFFIXES extension, folders
    holding ``run.json`` (CSV form) or ``metadata.yaml`` (ROS 2 bag);
    files matching the map's ``files.pattern`` for a delimited map (sidecars
    ``<run>.run.json`` aside)."""
    root = Path(root)
    cmap = load_channel_map(channel_map)
    if not root.exists():
        raise IngestError(root, None, "no such file or folder")
    if cmap.format == "delimited":
        if root.is_file():
            return [root]
        return sorted(p for p in root.rglob(cmap.file_pattern or "*")
                      if p.is_file() and not p.name.endswith(SIDECAR_SUFFIX))
    if root.is_file():
        return [root] if root.suffix.lower() in RUN_SUFFIXES else []
    bags = {p.parent for p in root.rglob(ROS2_METADATA)}
    found = [p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in RUN_SUFFIXES
             and p.parent not in bags]
    found += [p.parent for p in root.rglob("run.json")]
    return sorted(found + list(bags))


def read_campaign(root: str | Path,
                  channel_map: "str | Path | ChannelMap | None" = None) -> CampaignRead:
    """Read every run under ``root``; a bad run becomes a failure, the batch goes on."""
    cmap = load_channel_map(channel_map)
    result = CampaignRead(root=Path(root))
    for path in find_runs(root, cmap):
        try:
            result.runs.append(read_run(path, cmap))
        except IngestError as exc:
            result.failures.append(exc)
        except Exception as exc:  # one line per run, the batch goes on
            result.failures.append(IngestError(path, None, f"internal error while reading "
                                               f"({type(exc).__name__}: {exc}); please report it"))
    return result
