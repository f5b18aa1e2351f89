"""The wheel of a WPM CSV as an FMI 2.0 co-simulation FMU (docs/wpm-csv.md, "FMU"): inputs
wheel load and slip, outputs DP, torque, sinkage, motion resistance and their 95 %
half-widths, answered by libswtwpm (libswtwpm/fmi2_wheel.c) from the CSV embedded as
``resources/wpm.csv``: no Python at run time. The archive: ``modelDescription.xml``,
``binaries/linux64/swtwpm_wheel.so`` (the library built at install), ``resources/wpm.csv``.
"""

from __future__ import annotations

import csv
import io
import uuid
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

from swtlab_base.atomic import write_atomically
from wpm_export.clib import CWheelPerformanceModule, library_path

MODEL_IDENTIFIER = "swtwpm_wheel"
#: (name, value reference, unit, description) of the outputs; half-widths at 20 + i, 30 + i
OUTPUTS = (("dp_n", 10, "N", "drawbar pull"), ("torque_nm", 11, "N.m", "driving torque"),
           ("sinkage_m", 12, "m", "sinkage"), ("resistance_n", 13, "N", "motion resistance"))


def _variable(name: str, reference: int, kind: str, causality: str, description: str,
              variability: str = "continuous", start: str | None = None,
              unit: str | None = None) -> str:
    attributes = (f' unit={quoteattr(unit)}' if unit else "") + \
        (f' start={quoteattr(start)}' if start is not None else "")
    return (f'    <ScalarVariable name={quoteattr(name)} valueReference="{reference}" '
            f'causality="{causality}" variability="{variability}"'
            f' description={quoteattr(description)}>\n      <{kind}{attributes}/>\n'
            "    </ScalarVariable>")


def model_description(soil: str, wheel: str, multipass: int, load_n: float,
                      source: str) -> str:
    """modelDescription.xml of the wheel FMU, the set (soil, wheel, multipass) as parameters'
    start values and ``load_n`` as the load input's."""
    variables = [
        _variable("load_n", 0, "Real", "input", "wheel load", start=repr(load_n), unit="N"),
        _variable("slip", 1, "Real", "input", "slip (fraction, driving (r*w - v)/(r*w))",
                  start="0.0", unit="1"),
        _variable("multipass", 2, "Integer", "parameter", "passes over the soil before",
                  "fixed", str(multipass)),
        _variable("allow_extrapolation", 3, "Boolean", "parameter",
                  "answer outside the tested loads (linear, with a warning)", "fixed", "false"),
        _variable("soil", 4, "String", "parameter", "soil of the curves", "fixed", soil),
        _variable("wheel", 5, "String", "parameter", "wheel of the curves", "fixed", wheel),
    ]
    for name, reference, unit, description in OUTPUTS:
        variables.append(_variable(name, reference, "Real", "output", description, unit=unit))
    for name, reference, unit, description in OUTPUTS:
        variables.append(_variable(f"{name}_conf95", reference + 10, "Real", "output",
                                   f"95 % confidence half-width of the {description}",
                                   unit=unit))
        variables.append(_variable(f"{name}_pred95", reference + 20, "Real", "output",
                                   f"95 % prediction half-width (one run) of the {description}",
                                   unit=unit))
    variables.append(_variable("status", 40, "Integer", "output",
                               "0 ok, > 0 warnings (1 slip outside the fitted range, 2 load "
                               "extrapolated), < 0 the libswtwpm error code", "discrete"))
    outputs = [i + 1 for i, v in enumerate(variables) if 'causality="output"' in v]
    unknowns = "\n".join(f'      <Unknown index="{i}" dependencies="1 2"/>' for i in outputs)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{MODEL_IDENTIFIER}"
  guid="{{{uuid.uuid5(uuid.NAMESPACE_URL, source)}}}"
  description={quoteattr(f"Wheel Performance Module of {wheel} on {soil}, multipass "
                         f"{multipass} (swtlab WPM CSV, libswtwpm)")}
  generationTool="swtlab" variableNamingConvention="flat" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="false" canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"/>
  <UnitDefinitions>
    <Unit name="N"><BaseUnit kg="1" m="1" s="-2"/></Unit>
    <Unit name="N.m"><BaseUnit kg="1" m="2" s="-2"/></Unit>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="1"/>
  </UnitDefinitions>
  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="0.01"/>
  <ModelVariables>
{chr(10).join(variables)}
  </ModelVariables>
  <ModelStructure>
    <Outputs>
{unknowns}
    </Outputs>
    <InitialUnknowns>
{unknowns}
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""


def _one_set(text: str, soil: str, wheel: str, multipass: int) -> str:
    """The WPM CSV text with the rows of one curve set only (header and comments kept)."""
    out = []
    for line in text.splitlines():
        fields = next(csv.reader([line]), [])
        if line.startswith("#") or not line.strip() or fields[:2] == ["soil", "wheel"] or (
                [f.strip() for f in fields[:3]] == [soil, wheel, str(multipass)]):
            out.append(line)
    return "\n".join(out) + "\n"


def build_fmu(wpm_csv, out, *, soil=None, wheel=None, multipass=None) -> dict:
    """Write the FMU of the one curve set of ``wpm_csv`` matching soil/wheel/multipass to
    ``out`` (atomically); the CSV is read by libswtwpm first (its errors:
    :class:`WpmFormatError`, :class:`WpmSelectionError`). Returns the set and the path."""
    wpm = CWheelPerformanceModule(wpm_csv)
    set_soil, set_wheel, set_multipass = wpm.sets()[wpm.select(soil, wheel, multipass)]
    loads = wpm.tested_loads(soil=set_soil, wheel=set_wheel, multipass=set_multipass)
    load_n = loads[0] if loads else 1.0
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", model_description(
            set_soil, set_wheel, set_multipass, load_n, Path(wpm_csv).read_text()))
        archive.write(library_path(), f"binaries/linux64/{MODEL_IDENTIFIER}.so")
        text = Path(wpm_csv).read_text(encoding="utf-8-sig")
        archive.writestr("resources/wpm.csv",
                         _one_set(text, set_soil, set_wheel, set_multipass))
    write_atomically(out, buffer.getvalue())
    return {"fmu": str(out), "soil": set_soil, "wheel": set_wheel, "multipass": set_multipass}

