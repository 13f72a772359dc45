"""Package layout (the rest of the metadata is in pyproject.toml).

The repository keeps the design's four top-level folders, but only ``gsr`` is installed as a top-level
import name: the upper layers' folders install under its namespace, so a user's environment gains no
generic ``skills``, ``perception`` or ``benchmarks`` package (docs/architecture.md, "Packages").
"""

from setuptools import find_packages, setup

#: import name -> folder in the repository, lowest layer first
LAYER_FOLDERS = {"gsr.perception": "perception", "gsr.skills": "skills", "gsr.benchmarks": "benchmarks"}

packages = find_packages(include=["gsr", "gsr.*"])
for name, folder in LAYER_FOLDERS.items():
    packages += [name] + [f"{name}.{sub}" for sub in find_packages(folder)]

setup(packages=packages, package_dir=dict(LAYER_FOLDERS))
