"""Loading libfemcod.so and declaring its functions (ctypes; the header is src/capi/femcod.h).

ctypes is in the standard library, so the package installs without a compiler, and it
releases the GIL for the length of every foreign call: a solve runs without the GIL, and
the progress function takes it back only while it runs.
"""
import ctypes
import ctypes.util
import os
import shutil

#: Status codes (the femcod command's exit codes).
OK, USAGE, BAD_INPUT, NUMERICAL, IO, STOPPED = 0, 2, 3, 4, 5, 6

PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_double, ctypes.c_double,
                            ctypes.c_void_p)


def _blas_environment():
    """What the femcod program sets before OpenBLAS loads (app/femcod_start_environment.f90), so
    that a solve here runs the same BLAS kernels as on the command line and gives its
    answer to the last bit: the core from the CPU's flags (avx512f: SkylakeX, avx2:
    Haswell) and a short wait of idle BLAS threads. A user's own values are kept."""
    if "OPENBLAS_CORETYPE" not in os.environ:
        try:
            with open("/proc/cpuinfo") as f:
                for line in f:
                    if line.startswith("flags"):
                        words = line.split()
                        if "avx512f" in words:
                            os.environ["OPENBLAS_CORETYPE"] = "SkylakeX"
                        elif "avx2" in words:
                            os.environ["OPENBLAS_CORETYPE"] = "Haswell"
                        break
        except OSError:
            pass
    os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")


def library_path():
    """Where libfemcod.so is: $FEMCOD_LIBRARY; else the wheel's own (femcod/_native/lib, with
    the libraries it needs beside the package in femcod.libs); else beside the installed
    femcod program (PREFIX/lib next to PREFIX/bin/femcod, where setup.sh puts both); else
    the loader's."""
    given = os.environ.get("FEMCOD_LIBRARY")
    if given:
        return given
    bundled = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_native", "lib", "libfemcod.so")
    if os.path.exists(bundled):
        return bundled
    program = shutil.which("femcod")
    if program:
        candidate = os.path.join(os.path.dirname(os.path.realpath(program)), os.pardir, "lib", "libfemcod.so")
        if os.path.exists(candidate):
            return os.path.normpath(candidate)
    found = ctypes.util.find_library("femcod")
    if found:
        return found
    raise OSError("libfemcod.so not found: bash setup.sh builds and installs it beside the femcod program "
                  "(PREFIX/lib); or set FEMCOD_LIBRARY to its path")


def _declare(lib):
    c_int, c_double, c_char_p, c_void_p = ctypes.c_int, ctypes.c_double, ctypes.c_char_p, ctypes.c_void_p
    c_size_t, c_int64 = ctypes.c_size_t, ctypes.c_int64
    p_double, p_int = ctypes.POINTER(c_double), ctypes.POINTER(c_int)
    table = {
        "femcod_create": (c_void_p, []),
        "femcod_destroy": (None, [c_void_p]),
        "femcod_version": (c_int, [c_char_p, c_size_t]),
        "femcod_option_names": (c_int, [c_char_p, c_size_t]),
        "femcod_message": (c_int, [c_void_p, c_char_p, c_size_t]),
        "femcod_set_threads": (c_int, [c_int]),
        "femcod_set_heights": (c_int, [c_void_p, c_int, c_double, p_double, p_double, c_double, c_double, c_int]),
        "femcod_set_problem": (c_int, [c_void_p, c_int, c_double, p_double, p_double, p_double, p_double, c_int,
                                       c_char_p]),
        "femcod_read_deck": (c_int, [c_void_p, c_char_p]),
        "femcod_read_heights": (c_int, [c_void_p, c_char_p, c_double, c_int, c_double, c_double]),
        "femcod_warnings": (c_int, [c_void_p, c_char_p, c_size_t]),
        "femcod_write_deck": (c_int, [c_void_p, c_char_p, c_int]),
        "femcod_problem_size": (c_int, [c_void_p, p_int]),
        "femcod_get_problem": (c_int, [c_void_p, p_double, p_int, p_double, p_double, p_double, p_double]),
        "femcod_get_label": (c_int, [c_void_p, c_char_p, c_size_t]),
        "femcod_set_option": (c_int, [c_void_p, c_char_p, c_char_p]),
        "femcod_clear_options": (c_int, [c_void_p]),
        "femcod_solve": (c_int, [c_void_p, PROGRESS, c_void_p]),
        "femcod_state_count": (c_int, [c_void_p, p_int]),
        "femcod_value_names": (c_int, [c_void_p, c_int, c_char_p, c_size_t]),
        "femcod_state_value": (c_int, [c_void_p, c_int, c_char_p, p_double]),
        "femcod_state_map": (c_int, [c_void_p, c_int, c_char_p, p_double, c_int64]),
        "femcod_history_length": (c_int, [c_void_p, p_int]),
        "femcod_history": (c_int, [c_void_p, c_char_p, p_double, c_int64]),
        "femcod_write_results": (c_int, [c_void_p, c_char_p, c_int]),
        "femcod_report": (c_int, [c_void_p, c_char_p, c_char_p, c_int, c_char_p, c_size_t]),
    }
    for name, (restype, argtypes) in table.items():
        f = getattr(lib, name)
        f.restype = restype
        f.argtypes = argtypes
    return lib


_lib = None


def lib():
    """The loaded library (loaded on first use)."""
    global _lib
    if _lib is None:
        _blas_environment()
        _lib = _declare(ctypes.CDLL(library_path()))
    return _lib
