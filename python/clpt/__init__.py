"""clpt — the OpenCL path tracer, from Python (docs/api.md).

    import clpt
    img = clpt.render("scene.glb", spp=64, device="cpu", seed=1)   # float32 (H, W, 3)

A thin layer over the C API (include/clpt/clpt.h) through ctypes, on the libclpt.so
bundled beside this file. Settings are the command line's options: `spp=64` is
`--spp 64`, `max_depth=4` is `--max-depth 4`.
"""
import ctypes
import os
import signal
import threading

import numpy as np

__all__ = ["Error", "Cancelled", "Scene", "devices", "load", "render", "version"]

_lib = ctypes.CDLL(os.path.join(os.path.dirname(os.path.abspath(__file__)), "libclpt.so"))

_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint, ctypes.c_uint)
_FLOATS = ctypes.POINTER(ctypes.c_float)


class _Image(ctypes.Structure):
    _fields_ = [("width", ctypes.c_uint), ("height", ctypes.c_uint), ("rgb", _FLOATS), ("albedo", _FLOATS),
                ("normal", _FLOATS), ("depth", _FLOATS), ("spp", ctypes.c_uint)]


def _declare(name, restype, *argtypes):
    f = getattr(_lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    return f


_P = ctypes.c_void_p
_version = _declare("clpt_version", ctypes.c_char_p)
_context_create = _declare("clpt_context_create", _P)
_context_free = _declare("clpt_context_free", None, _P)
_last_error = _declare("clpt_last_error", ctypes.c_char_p, _P)
_set_devices = _declare("clpt_context_set_devices", ctypes.c_int, _P, ctypes.c_char_p)
_device_count = _declare("clpt_device_count", ctypes.c_size_t, _P)
_device_str = {k: _declare("clpt_device_" + k, ctypes.c_char_p, _P, ctypes.c_size_t)
               for k in ("name", "kind", "type", "platform")}
_device_index = _declare("clpt_device_index", ctypes.c_int, _P, ctypes.c_size_t)
_scene_load = _declare("clpt_scene_load", ctypes.c_int, _P, ctypes.c_char_p, ctypes.POINTER(_P))
_scene_set = _declare("clpt_scene_set", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p)
_scene_free = _declare("clpt_scene_free", None, _P)
_settings_create = _declare("clpt_settings_create", _P, _P)
_settings_set = _declare("clpt_settings_set", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p)
_settings_free = _declare("clpt_settings_free", None, _P)
_render_size = _declare("clpt_render_size", ctypes.c_int, _P, _P, ctypes.POINTER(ctypes.c_uint),
                        ctypes.POINTER(ctypes.c_uint))
_render = _declare("clpt_render", ctypes.c_int, _P, _P, ctypes.POINTER(_Image), _PROGRESS, _P)

_INTERRUPTED, _NOTHING_RENDERED = 6, 7


class Error(Exception):
    """A failed call: the message the command line would print; `status` is its exit code."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class Cancelled(Error):
    """The progress callback returned True: `result` holds the samples finished (None
    when none were)."""

    def __init__(self, message, status, result):
        super().__init__(message, status)
        self.result = result


def version():
    return _version().decode()


class _Context:
    """A C context: its devices and its last error. Freed with the object."""

    def __init__(self, device=None):
        self.ptr = _context_create()
        if not self.ptr:
            raise MemoryError("clpt_context_create")
        if device is not None:
            self.check(_set_devices(self.ptr, str(device).encode()))

    def check(self, status):
        if status != 0:
            raise Error(_last_error(self.ptr).decode(), status)

    def __del__(self):
        if getattr(self, "ptr", None):
            _context_free(self.ptr)
            self.ptr = None


def devices():
    """Every device, as `clpt --list-devices` lists them; `index` is what device=
    takes for an OpenCL device (None for the scalar device, chosen as "scalar")."""
    ctx = _Context()
    out = []
    for i in range(_device_count(ctx.ptr)):
        d = {k: f(ctx.ptr, i).decode() for k, f in _device_str.items()}
        index = _device_index(ctx.ptr, i)
        d["index"] = index if index >= 0 else None
        out.append(d)
    return out


def _text(value):
    """A Python value as the command line writes it: True "1", (1, 2, 3) "1,2,3"."""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, (list, tuple, np.ndarray)):
        return ",".join(repr(float(v)) if isinstance(v, float) else str(v) for v in value)
    return str(value)


_AOVS = ("albedo", "normal", "depth")


class Scene:
    """A scene read from a file in any format clpt reads; set() edits it as --set does."""

    def __init__(self, path, device=None):
        self._ctx = _Context(device)
        ptr = _P()
        self._ctx.check(_scene_load(self._ctx.ptr, os.fspath(path).encode(), ctypes.byref(ptr)))
        self._ptr = ptr

    def __del__(self):
        if getattr(self, "_ptr", None):
            _scene_free(self._ptr)
            self._ptr = None

    def set(self, key, value):
        """Sets a parameter by path: "camera.fov", 40; "material.red.albedo", (0.8, 0.2, 0.2)."""
        self._ctx.check(_scene_set(self._ptr, key.encode(), _text(value).encode()))
        return self

    def render(self, aovs=(), progress=None, **settings):
        """Renders: float32 (H, W, 3) linear RGB; with aovs (any of "albedo", "normal",
        "depth") a dict of those and "rgb" (depth is (H, W)). progress(done, total) is
        called about every 0.1 s; returning True cancels (Cancelled). Ctrl-C stops the
        render and raises KeyboardInterrupt."""
        for a in aovs:
            if a not in _AOVS:
                raise ValueError("aovs: %r is not one of %s" % (a, ", ".join(_AOVS)))
        ctx = self._ctx
        if "device" in settings:
            ctx.check(_set_devices(ctx.ptr, str(settings.pop("device")).encode()))
        st = _settings_create(ctx.ptr)
        try:
            for name, value in settings.items():
                if value is not None:
                    ctx.check(_settings_set(st, name.replace("_", "-").encode(), _text(value).encode()))
            return self._render(st, aovs, progress)
        finally:
            _settings_free(st)

    def _render(self, st, aovs, progress):
        ctx = self._ctx
        w, h = ctypes.c_uint(), ctypes.c_uint()
        ctx.check(_render_size(self._ptr, st, ctypes.byref(w), ctypes.byref(h)))
        shape = (h.value, w.value)
        out = {"rgb": np.zeros(shape + (3,), np.float32)}
        for a in aovs:
            out[a] = np.zeros(shape if a == "depth" else shape + (3,), np.float32)
        img = _Image(w.value, h.value, *(out[k].ctypes.data_as(_FLOATS) if k in out else None
                                         for k in ("rgb",) + _AOVS), 0)
        state = {"interrupt": False, "error": None}

        # Runs on this thread while the C render waits. A KeyboardInterrupt must not
        # escape into C (ctypes would only print it), and Python raises it where the
        # next Python code runs, which may be this function's first line: so while
        # rendering, SIGINT only sets a flag (_sigint_flag), which cancels here.
        def on_progress(_user, done, total):
            try:
                if not state["interrupt"] and not (progress is not None and progress(done, total)):
                    return 0
            except KeyboardInterrupt:
                state["interrupt"] = True
            except BaseException as e:  # an error in the callback stops the render too
                state["error"] = e
            return 1

        with _sigint_flag(state):
            status = _render(self._ptr, st, ctypes.byref(img), _PROGRESS(on_progress), None)
        if state["interrupt"]:
            raise KeyboardInterrupt("clpt: render stopped")
        if state["error"] is not None:
            raise state["error"]
        result = out if aovs else out["rgb"]
        if status in (_INTERRUPTED, _NOTHING_RENDERED) and progress is not None:
            raise Cancelled(_last_error(ctx.ptr).decode(), status, result if status == _INTERRUPTED else None)
        ctx.check(status)
        return result


class _sigint_flag:
    """While rendering on the main thread with Python's own SIGINT handler, Ctrl-C sets
    state["interrupt"] instead of raising; the old handler is put back after."""

    def __init__(self, state):
        self.state, self.old = state, None

    def _handler(self, _sig, _frame):
        self.state["interrupt"] = True

    def __enter__(self):
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self.old = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc):
        if self.old is not None:
            signal.signal(signal.SIGINT, self.old)
        return False


def load(path, device=None):
    """Reads a scene (clpt's format, pbrt-v4, glTF, .obj/.ply, the courses' format)."""
    return Scene(path, device)


def render(path, aovs=(), progress=None, device=None, **settings):
    """Reads and renders a scene: clpt.render("scene.glb", spp=64, device="cpu", seed=1)."""
    return Scene(path, device).render(aovs=aovs, progress=progress, **settings)
