"""The built-in exporters: the document as JSON or YAML, and the firmware C header."""

from __future__ import annotations

import json

from .._validation import refuse_options
from ..errors import MissingDependencyError
from ..results.calibration import Calibration
from ..thermal.model import ThermalCalibration
from . import register_exporter

__all__ = ["c_header", "json_text", "yaml_text"]


def json_text(obj, **options) -> str:
    """The file's current-version document as indented JSON (old versions come out upgraded)."""
    refuse_options(options, (), "json export")
    return json.dumps(obj.to_document(), indent=2, allow_nan=False) + "\n"


def yaml_text(obj, **options) -> str:
    """The same document as YAML; it loads back equal to the JSON."""
    refuse_options(options, (), "yaml export")
    try:
        import yaml
    except ImportError:
        raise MissingDependencyError("YAML export needs pyyaml: pip install 'gyrocal[yaml]'") from None
    return yaml.safe_dump(obj.to_document(), sort_keys=False, default_flow_style=None, width=120)


def c_header(obj, *, prefix: str = "gyrocal", **options) -> str:
    """The calibration's firmware header (its ``c_header`` method)."""
    refuse_options(options, ("prefix",), "c-header export")
    return obj.c_header(prefix=prefix)


register_exporter("json", None, json_text, suffix=".json")
register_exporter("yaml", None, yaml_text, suffix=".yaml")
register_exporter("c-header", (Calibration, ThermalCalibration), c_header, suffix=".h")
