# SPDX-License-Identifier: Apache-2.0
# pip install ./bindings/python: pure Python (ctypes over the installed
# libpose), built with the system's setuptools, nothing downloaded. The
# version follows libpose's (a test checks they agree).
from setuptools import setup

setup(
    name="pose",
    version="0.2.0",
    description="Python bindings of libpose: pose a virtual patient's whole anatomy in real time",
    license="Apache-2.0",
    packages=["pose"],
    python_requires=">=3.8",
    extras_require={"numpy": ["numpy"]},
)
