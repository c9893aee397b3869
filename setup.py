"""Package list for setuptools.

The three domain folders (``perception/``, ``control/``, ``fusion/``) sit at the
top of the repository but install as subpackages of ``aiorobot`` through the
``package-dir`` mapping in pyproject.toml; ``find_packages`` cannot see that
mapping, so the package list is assembled here.
"""
from setuptools import find_packages, setup

DOMAINS = ("perception", "control", "fusion")

packages = find_packages(include=["aiorobot", "aiorobot.*"])
for folder in DOMAINS:
    packages.append(f"aiorobot.{folder}")
    packages += [f"aiorobot.{folder}.{sub}" for sub in find_packages(folder)]

setup(packages=packages)
