"""Report section: slip read from track photos against encoder slip (RUAG SWT: below 1 %).

Registered as an optional section (:mod:`campaign_report.extensions`): it appears only
when runs of the campaign carry an ``image_slip`` result (track photos, docs/track-slip.md),
read from the campaign's results table.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from campaign_report.data import CampaignData
from campaign_report.extensions import Extension, register
from campaign_report.html import Image, Note, Section, Table
from campaign_report.images import to_png
from campaign_report.style import Palette
from swtlab_base.rounding import value_and_u

#: the agreement the RUAG campaign reports between photo and facility slip
AGREEMENT = 0.01


def _figure(rows, palette: Palette) -> Figure:
    fig = Figure(figsize=(5.5, 5.0))
    ax = fig.subplots()
    for _, row in rows.iterrows():
        ax.errorbar(100 * row["slip_mean"], 100 * row["image_slip_mean"],
                    yerr=100 * 2 * row["image_slip_se"], fmt=palette.marker(row["multipass"]),
                    color=palette.colour(row["load_set_n"]), capsize=3)
    top = 100 * float(np.nanmax(rows[["slip_mean", "image_slip_mean"]].to_numpy())) + 5
    line = np.array([0.0, top])
    ax.plot(line, line, color="0.3", lw=1, label="image = encoder")
    ax.fill_between(line, line - 1, line + 1, color="0.85", label="±1 percentage point")
    ax.set(xlabel="encoder slip (%)", ylabel="image slip from track photo (%)",
           xlim=(0, top), ylim=(0, top), title="Track-photo slip against encoder slip")
    ax.legend(handles=palette.legend_handles(sorted(set(rows["load_set_n"])),
                                             sorted(set(rows["multipass"])))
              + ax.get_legend_handles_labels()[0], fontsize=8, loc="upper left")
    fig.tight_layout()
    return fig


def image_slip_section(data: CampaignData, palette: Palette) -> Section | None:
    """Image slip beside encoder slip for every run with track photos; None without any."""
    table = data.results
    if "image_slip_mean" not in table or "slip_mean" not in table:
        return None
    rows = table[table["image_slip_mean"].notna() & table["slip_mean"].notna()]
    if rows.empty:
        return None
    difference = rows["image_slip_mean"] - rows["slip_mean"]
    worst = float(np.max(np.abs(difference)))
    cells = [[r.run_id, f"{r.load_set_n:g}", f"{100 * r.slip_mean:.2f}",
              " ± ".join(value_and_u(r.image_slip_mean, r.image_slip_se, 100.0)),
              f"{100 * d:+.2f}"] for r, d in zip(rows.itertuples(), difference)]
    verdict = "within" if worst < AGREEMENT else "NOT within"
    return Section("image-slip", "Image slip against encoder slip", [
        Note(f"Slip read from the grouser marks in photos of the track, beside the encoder "
             f"slip of the same run. Largest difference {100 * worst:.2f} percentage points: "
             f"{verdict} the 1 % the RUAG SWT campaign found.", warning=worst >= AGREEMENT),
        Image("image-slip-figure", "image slip against encoder slip",
              to_png(_figure(rows, palette))[0]),
        Table(["run", "load (N)", "encoder slip (%)", "image slip (%) ± SE",
               "image − encoder (points)"], cells, numeric=frozenset({1, 2, 3, 4}))])


register(Extension("image-slip", image_slip_section))
