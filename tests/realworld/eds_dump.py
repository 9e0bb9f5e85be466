"""Dumps what the python `canopen` library reads from EDS/DCF files, as one JSON object:
{file: {"objects": {"IIII:SS": [name, data_type]}, "mapping": {"IIII:SS": value}} or
{"error": text}}. Used by tests/eds_import.rs as the reference where the library can read
a file.

    python3 eds_dump.py FILE...
"""
import json
import sys

import canopen
from canopen.objectdictionary import ODArray, ODRecord, ODVariable


def variables(od):
    for obj in od.values():
        if isinstance(obj, ODVariable):
            yield obj
        elif isinstance(obj, (ODRecord, ODArray)):
            for sub in obj.values():
                yield sub


def dump(path):
    try:
        od = canopen.import_od(path, node_id=5)
    except Exception as e:  # the library fails on some real files: no reference then
        return {"error": f"{type(e).__name__}: {e}"}
    objects, mapping = {}, {}
    for v in variables(od):
        key = f"{v.index:04X}:{v.subindex:02X}"
        objects[key] = [v.name, v.data_type]
        in_map = 0x1600 <= v.index <= 0x17FF or 0x1A00 <= v.index <= 0x1BFF
        # A DCF's ParameterValue (`value`) is what the device is configured with.
        configured = v.value if getattr(v, "value", None) is not None else v.default
        if in_map and v.subindex > 0 and isinstance(configured, int):
            mapping[key] = configured
    return {"objects": objects, "mapping": mapping}


print(json.dumps({path: dump(path) for path in sys.argv[1:]}))
