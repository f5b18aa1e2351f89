"""Ingest: raw SWT runs (MCAP, CSV, or a lab's files through a channel map) -> ``Run``.

Public API: ``read_run``, ``find_runs``, ``read_campaign``, ``Run``, ``RunMetadata``,
``CampaignRead``, ``IngestError``, ``Problem``, ``load_channel_map``, ``ChannelMap``.
"""

from ingest.campaign import CampaignRead, find_runs, read_campaign
from ingest.channel_map import ChannelMap, load_channel_map, shipped_maps
from ingest.errors import IngestError, Problem
from ingest.metadata import CameraInfo, CameraTrackInfo, RunInfo, RunMetadata, SuspensionInfo
from ingest.raw import FrameIndex
from ingest.run import Run, read_run

__all__ = [
    "CameraInfo", "CameraTrackInfo", "CampaignRead", "ChannelMap", "FrameIndex", "IngestError",
    "Problem", "Run", "RunInfo", "RunMetadata", "SuspensionInfo", "find_runs",
    "load_channel_map", "read_campaign", "read_run", "shipped_maps",
]
