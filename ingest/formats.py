"""Which reader a run needs, by its content (magic bytes), not only by its extension.

``sniff`` names the format; ``ingest.run.read_raw_file`` hands the path to that format's
reader (there, so that the readers may use the names here: imports point one way).
"""

from __future__ import annotations

from pathlib import Path

from ingest.errors import IngestError

MCAP_MAGIC = b"\x89MCAP0\r\n"
HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
MAT_TEXT = b"MATLAB "  # "MATLAB 5.0 MAT-file, ..." (v5 to v7) or "MATLAB 7.3 MAT-file, ..."
MAT73_HDF5_OFFSET = 512  # MATLAB v7.3: a 512-byte MATLAB header (user block), then HDF5
TDMS_MAGIC = b"TDSm"
ROSBAG1_MAGIC = b"#ROSBAG V2.0"
ROS2_METADATA = "metadata.yaml"
ROS_FORMATS = ("rosbag1", "rosbag2", "mcap_cdr")
#: what ``sniff`` returns, one reader each
FORMATS = ("mcap", "mcap_cdr", "hdf5", "mat5", "mat73", "tdms", "rosbag1", "rosbag2", "csv_run")

#: the reader to try on a file whose first bytes are none of the above (a damaged file)
BY_SUFFIX = {".mcap": "mcap", ".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat5",
             ".tdms": "tdms", ".bag": "rosbag1"}


def sniff(path: Path) -> str:
    """The format of a run file or folder, from its first bytes (or a folder's marker file);
    the extension only decides for a file whose first bytes are no known format's."""
    path = Path(path)
    if path.is_dir():
        if (path / ROS2_METADATA).is_file():
            return "rosbag2"
        if (path / "run.json").is_file():
            return "csv_run"
        raise IngestError(path, None, "not a run: a folder with no run.json (CSV form) and no "
                          "metadata.yaml (ROS 2 bag)")
    try:
        with open(path, "rb") as stream:
            head = stream.read(MAT73_HDF5_OFFSET + len(HDF5_MAGIC))
    except OSError as exc:
        raise IngestError(path, None, f"cannot read file: {exc.strerror or exc}") from None
    if head.startswith(MCAP_MAGIC):
        return "mcap_cdr" if _mcap_is_cdr(path) else "mcap"
    if head.startswith(HDF5_MAGIC):
        return "hdf5"
    if head.startswith(MAT_TEXT) and b"MAT-file" in head[:116]:
        if head[MAT73_HDF5_OFFSET:].startswith(HDF5_MAGIC):
            return "mat73"
        return "mat5"
    if head.startswith(TDMS_MAGIC):
        return "tdms"
    if head.startswith(ROSBAG1_MAGIC):
        return "rosbag1"
    if path.suffix.lower() in BY_SUFFIX:  # unknown bytes: that format's reader says what is wrong
        return BY_SUFFIX[path.suffix.lower()]
    raise IngestError(path, None, f"not a run: unknown format (first bytes {head[:8]!r}); "
                      "swtlab reads MCAP, HDF5, MATLAB .mat, NI TDMS, ROS 1/2 bags, CSV run "
                      "folders "
                      "(for a text log pass its channel map, e.g. "
                      "channel_map='cmu_3d_terramechanics')")


def is_ros_bag(path: Path) -> bool:
    """True for a ROS 1 bag, a ROS 2 bag folder or a CDR MCAP (False for text and the rest)."""
    try:
        return sniff(path) in ROS_FORMATS
    except IngestError:
        return False


def _mcap_is_cdr(path: Path) -> bool:
    """True when the MCAP's channels carry CDR (ROS 2) messages rather than the spec's JSON."""
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as stream:
            summary = make_reader(stream).get_summary()
    except Exception:  # a damaged file goes to the spec reader, which says why
        return False
    if summary is None:
        return False
    return any(c.message_encoding == "cdr" for c in summary.channels.values())

