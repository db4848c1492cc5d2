"""fogcl: deferred and volumetric fog on OpenCL devices and in C++ (docs/python.md)."""

from ._fogcl import *  # noqa: F401,F403
from ._fogcl import version  # noqa: F401
