"""gsr.benchmarks.perception: its __init__ names a public API that resolves, and importing it stays light."""

import subprocess
import sys

import gsr.benchmarks.perception as package
import pytest


def test_every_public_name_resolves_to_its_module() -> None:
    for name in package.__all__:
        value = getattr(package, name)
        if callable(value):  # functions and classes are defined in one of the package's modules
            assert value.__module__.startswith("gsr.benchmarks.perception."), name
        else:  # constants: present (a missing one raises AttributeError above)
            assert value is not None, name


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no_such_name"):
        _ = package.no_such_name


def test_importing_the_package_loads_neither_pybullet_nor_the_pipeline() -> None:
    code = (
        "import sys, gsr.benchmarks.perception\n"
        "print(sorted(m for m in ('pybullet', 'gsr.perception.pipeline', 'gsr.benchmarks.perception.eval')"
        " if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
