"""Progress bars: shown on a terminal, silent with ``--quiet`` or when output is not a terminal."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")


def progress(items: Iterable[T], *, desc: str, total: int | None = None,
             quiet: bool = False) -> Iterator[T]:
    disable = quiet or not sys.stderr.isatty()
    yield from tqdm(items, desc=desc, total=total, disable=disable, unit="run", leave=False)
