"""The binding of the C library, what ``steadystep/__init__.py`` exports (docs/python.md).

cffi in ABI mode over libsteadystep_lab (installed beside this package in ``_native/``), its declarations prepared
from the headers when the package is built (``_cdef_build.py``, run by CMakeLists.txt; its output,
``_native_ffi.py``, is installed here): ``_native`` loads the library and turns statuses into errors, ``_structs``
views C structs, ``_handles`` and ``_libode`` reach the ODE world a program built with odepy or PyODE (``pyode``);
``enums`` are the C enums, ``convert`` the pure conversions, ``registry``, ``stepper`` and ``stepping`` the library's
objects. Nothing here imports the lab, the report or the audit.
"""
