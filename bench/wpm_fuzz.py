"""Mutated WPM CSVs through libswtwpm under AddressSanitizer and UBSan (issue 37.2): the C
reader must return an error code and a message for every malformed file and never crash,
read out of bounds, overflow, leak or hit undefined behaviour, whatever it reads.

Seeds: WPM CSVs written by swtlab's writer (in-family: the writer is the one the format page
describes), in every header variant a reader accepts (with uncertainty and braked branch,
without the uncertainty columns, without both, without ``wheel_geometry``; one, two and
three tested loads). Each mutant applies one to three mutations: bytes (flip, insert,
delete, duplicate, truncate), lines (delete, duplicate, swap, insert), one field replaced by
a hostile value (non-finite, huge, tiny, empty, quoted, underscores, hexadecimal, another
row's value), one ``wheel_geometry`` value replaced by hostile JSON, encodings (BOM, CRLF,
a non-UTF-8 byte, NUL, Unicode line separators). ``mutants(seeds, n, seed)`` is the same
set on every machine. The driver (libswtwpm/tools/fuzz_driver.c) opens each file and asks
every set and quantity forward, band and inverse queries at edge loads, slips and targets.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

import numpy as np

from bench.fuzz_inputs import HOSTILE_JSON

ROOT = Path(__file__).resolve().parents[1]
C_SOURCES = sorted((ROOT / "libswtwpm").glob("*.c"))
DRIVER = ROOT / "libswtwpm" / "tools" / "fuzz_driver.c"
SANITIZE = ("-fsanitize=address,undefined", "-fno-sanitize-recover=all")

HOSTILE_FIELDS = ("", "nan", "NaN", "inf", "-inf", "Infinity", "1e309", "-1e309", "1e-320",
                  "0", "-0", "0.0", "1_000", "_1", "1__0", "1_", "0x10", "1e", "e5", ".", "-",
                  "+.5", "5.", "9" * 400, "3.5", "-1", "-1.5", "1.0000000001", "8", "2", "3",
                  "7", "99999999999999999999999", '"', '""', '"a,b"', "é", "1,2", " 3 ",
                  "1e-5", "-0.1", "0.6", "1", "dp_n", "N", "N*m", "torque_nm", "\t", "#",
                  "１２", "1 2", "1e400 2")
HOSTILE_LINES = ("", "# x: y", "#", "# format: swtlab-wpm/2", ",,,,", "a,b,c", '"', "# : ",
                 "soil,wheel")
LINE_BREAKS = ("\u2028", "\x85", "\x0b", "\x0c", "\r", "\x1c")


def seed_texts(wpm_csv_text: str) -> list[str]:
    """The header variants a reader accepts, made from one full WPM CSV text."""
    lines = wpm_csv_text.splitlines()
    comments = [x for x in lines if x.startswith("#")]
    header, rows = lines[len(comments)], lines[len(comments) + 1:]
    cut = [x.rsplit(",", 3)[0] for x in [header, *rows]]  # without the uncertainty columns
    plain = [x.rsplit(",", 2)[0] for x in cut]  # ... and the braked branch
    loads = sorted({float(r.split(",")[3]) for r in rows})
    out = ["\n".join([*comments, header, *rows]) + "\n",
           "\n".join([*comments, *cut]) + "\n",
           "\n".join([*comments, *plain]) + "\n",
           "\n".join([x for x in comments if "wheel_geometry" not in x] + [header, *rows])
           + "\n"]
    for keep in (loads[:1], loads[:2]):
        kept = [r for r in rows if float(r.split(",")[3]) in keep]
        out.append("\n".join([*comments, header, *kept]) + "\n")
    return out


def _mutate_bytes(rng, data: bytes) -> bytes:
    if not data:
        return bytes(rng.integers(0, 256, 8, dtype=np.uint8))
    i = int(rng.integers(0, len(data)))
    kind = int(rng.integers(0, 5))
    if kind == 0:
        return data[:i] + bytes([int(rng.integers(0, 256))]) + data[i + 1:]
    if kind == 1:
        return data[:i] + bytes(rng.integers(0, 256, int(rng.integers(1, 8)), dtype=np.uint8)) \
            + data[i:]
    if kind == 2:
        return data[:i] + data[i + int(rng.integers(1, 200)):]
    if kind == 3:
        j = min(len(data), i + int(rng.integers(1, 400)))
        return data[:j] + data[i:j] + data[j:]
    return data[:i]


def _mutate_lines(rng, text: str) -> str:
    lines = text.split("\n")
    i, j = int(rng.integers(0, len(lines))), int(rng.integers(0, len(lines)))
    kind = int(rng.integers(0, 4))
    if kind == 0:
        del lines[i]
    elif kind == 1:
        lines.insert(i, lines[j])
    elif kind == 2:
        lines[i], lines[j] = lines[j], lines[i]
    else:
        lines.insert(i, str(rng.choice(HOSTILE_LINES)))
    return "\n".join(lines)


def _mutate_field(rng, text: str) -> str:
    lines = text.split("\n")
    data = [k for k, x in enumerate(lines) if x and not x.startswith("#")]
    if not data:
        return text
    k = int(rng.choice(data))
    fields = lines[k].split(",")
    i = int(rng.integers(0, len(fields)))
    kind = int(rng.integers(0, 4))
    if kind == 0:
        fields[i] = str(rng.choice(HOSTILE_FIELDS))
    elif kind == 1:  # another row's value in this column (duplicates, other degrees)
        other = lines[int(rng.choice(data))].split(",")
        fields[i] = other[i] if i < len(other) else ""
    elif kind == 2:  # a number scaled or sign-flipped
        try:
            fields[i] = repr(float(fields[i]) * float(rng.choice([-1.0, 0.0, 1e-300, 1e300,
                                                                   1.0000001, 10.0])))
        except ValueError:
            fields[i] = str(rng.choice(HOSTILE_FIELDS))
    else:  # a field removed or added
        if rng.random() < 0.5:
            del fields[i]
        else:
            fields.insert(i, str(rng.choice(HOSTILE_FIELDS)))
    lines[k] = ",".join(fields)
    return "\n".join(lines)


def _mutate_geometry(rng, text: str) -> str:
    match = re.search(r"^# wheel_geometry: (.*)$", text, flags=re.M)
    if not match:
        return text
    try:
        table = json.loads(match.group(1))
        wheel = next(iter(table))
        key = str(rng.choice(sorted(table[wheel]) + ["mass_kg", "radius"]))
    except (ValueError, StopIteration, TypeError, AttributeError):
        return text
    kind = int(rng.integers(0, 4))
    if kind == 0:
        table[wheel][key] = "@@"  # replaced by hostile JSON text below
        body = json.dumps(table).replace('"@@"', str(rng.choice(HOSTILE_JSON)))
    elif kind == 1:
        table[wheel].pop(key, None)
        body = json.dumps(table)
    elif kind == 2:
        body = json.dumps({"other wheel": table[wheel]})
    else:
        body = json.dumps(table)
        cut = int(rng.integers(0, len(body)))
        body = body[:cut] + str(rng.choice(["{", "}", "[", '"', "\\u12", ":", "[" * 200]))\
            + body[cut:]
    return text[:match.start(1)] + body + text[match.end(1):]


def _mutate_encoding(rng, data: bytes) -> bytes:
    kind = int(rng.integers(0, 5))
    i = int(rng.integers(0, len(data) + 1))
    if kind == 0:
        return b"\xef\xbb\xbf" + data
    if kind == 1:
        return data.replace(b"\n", b"\r\n")
    if kind == 2:
        return data[:i] + bytes([int(rng.choice([0x80, 0xC3, 0xED, 0xF4, 0xFF, 0xE2]))]) \
            + data[i:]
    if kind == 3:
        return data[:i] + b"\x00" + data[i:]
    return data.replace(b"\n", str(rng.choice(LINE_BREAKS)).encode(), int(rng.integers(1, 4)))


def mutant(rng, seeds: list[str]) -> bytes:
    """One mutated WPM CSV: one to three mutations of a seed."""
    text = str(rng.choice(seeds))
    data = text.encode()
    for _ in range(int(rng.integers(1, 4))):
        kind = int(rng.integers(0, 5))
        if kind == 0:
            data = _mutate_bytes(rng, data)
        elif kind == 4:
            data = _mutate_encoding(rng, data)
        else:
            text = data.decode("utf-8", errors="surrogateescape")
            text = (_mutate_lines, _mutate_field, _mutate_geometry)[kind - 1](rng, text)
            data = text.encode("utf-8", errors="surrogateescape")
    return data


def write_mutants(seeds: list[str], n: int, seed: int, folder: Path) -> list[Path]:
    """``n`` mutants of ``seeds`` as files in ``folder`` (the same on every machine)."""
    rng = np.random.default_rng(seed)
    paths = []
    for i in range(n):
        path = folder / f"mutant_{i:05d}.csv"
        path.write_bytes(mutant(rng, seeds))
        paths.append(path)
    return paths


def build_driver(folder: Path, sanitize: bool = True) -> Path:
    """The fuzz driver compiled with the library's sources (gcc or $CC)."""
    out = folder / "swtwpm_fuzz"
    flags = ["-std=c99", "-g", "-O0" if sanitize else "-O2", *(SANITIZE if sanitize else ())]
    subprocess.run([os.environ.get("CC", "gcc"), *flags, f"-I{ROOT / 'libswtwpm'}", "-o",
                    str(out), *map(str, C_SOURCES), str(DRIVER), "-lm"], check=True)
    return out


def run_driver(driver: Path, paths: list[Path]) -> tuple[list[tuple[int, str]], int, str]:
    """``([(code, message) per file], exit code, sanitizer report)``; a finding stops the
    driver (no recovery) with a non-zero exit code and a report on standard error."""
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    done = subprocess.run([str(driver)], input="".join(f"{p}\n" for p in paths), text=True,
                          capture_output=True, env=env, errors="replace")
    results = []
    for line in done.stdout.splitlines():
        code, _, message = line.partition("\t")
        results.append((int(code), message))
    return results, done.returncode, done.stderr
