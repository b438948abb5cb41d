#!/usr/bin/env python3
"""Render one scene with VTK's unstructured-grid volume mappers and time them.

    python3 vtk_bench.py SCENE.json

Written for `zoovr bench --with-vtk PYTHON`, which writes SCENE.json and the mesh
(.vtu), runs this script, reads the `RESULT {json}` lines on stdout and the PNG
images written to the scene's "out" folder, and computes the image error itself.
Standard library + `vtk` only.

SCENE.json:
  mesh         absolute path of an XML unstructured grid (.vtu)
  array        name of the scalar array to render
  association  "point" | "cell"
  background   [r, g, b] in [0, 1]
  tf           {"colors": [[s, r, g, b], ...], "opacity": [[s, a], ...],
                "unit_distance": u}   (absolute scalar values, piecewise linear;
                extinction = a / u per world unit, VTK's unstructured convention)
  mappers      subset of pt, raycast-linear, raycast-partial, raycast-preint,
               raycast-homog, zsweep; run and reported in the given order
  warmup       untimed renders after the first render of a frame (int >= 0)
  repeats      timed renders after the warm-up (int >= 1)
  out          existing folder for the images OUT/vtk_MAPPER_TAG.png
  frames       [{"tag", "width", "height", "camera": {"position", "focal_point",
                 "view_up", "view_angle", "ortho", "parallel_scale"}}, ...]
  timeout_s    optional: seconds allowed to one mapper's process (default: none)

stdout: exactly one `RESULT {json}` line per (mapper, frame), mapper-major, frame-minor
order; nothing else.  Progress and VTK's own messages go to stderr.  Keys of a line:
  mapper, tag, first_s (first render of the frame, includes the mapper's setup),
  times_s (the timed repeats), median_s, min_s, max_s, tetra_s (tetrahedralisation,
  0 if none), read_s, context_s (empty render that creates the GL context, not in
  first_s), cells (cells the mapper drew), tetrahedralised, peak_rss_mb (of the
  mapper's process), image (absolute PNG path, 8-bit RGB, top row first), vtk_version;
  or, for a frame the mapper did not finish: mapper, tag, error.

Each mapper runs in a child process (`python vtk_bench.py --one MAPPER SCENE.json`),
so that a crash of one mapper (partial pre-integration can segfault on rays that run
along faces) loses only that mapper's remaining frames, which are then reported as
`RESULT {"mapper": M, "tag": T, "error": "..."}`.

Exit status: 0 when the script ran (even if mappers failed), 2 on a bad SCENE.json
or bad arguments, 3 when `import vtk` fails.
"""
import json
import os
import re
import resource
import signal
import statistics
import subprocess
import sys
import threading
import time

# Offscreen rendering on machines without a GPU (Mesa llvmpipe through EGL) and VTK's
# std::thread SMP backend.  Only defaults: values the user already set are kept.
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
os.environ.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")

MAPPERS = ("pt", "raycast-linear", "raycast-partial", "raycast-preint", "raycast-homog", "zsweep")

# Every mapper gets the mesh through vtkDataSetTriangleFilter (TetrahedraOnlyOn) first
# unless it holds only tetrahedra (timed as tetra_s): the ray caster and projected
# tetrahedra draw nothing for other cells, and VTK 9.7's ZSweep mapper, given
# hexahedra, leaves triangular holes in every cell (it draws, but wrongly); on the
# tetrahedralised mesh its image is close to the ray caster's.
NEEDS_TETRA = set(MAPPERS)

EXIT_BAD_SCENE = 2
EXIT_NO_VTK = 3

TAG_RE = re.compile(r"^[A-Za-z0-9_.+-]+$")
ANSI_RE = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def log(msg):
    sys.stderr.write("vtk_bench: " + msg + "\n")
    sys.stderr.flush()


def emit(obj):
    sys.stdout.write("RESULT " + json.dumps(obj) + "\n")
    sys.stdout.flush()


# ---------------------------------------------------------------------------- scene file
class SceneError(Exception):
    pass


def _num(v, key):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or v != v or v in (float("inf"), float("-inf")):
        raise SceneError("key '%s': expected a finite number, got %s" % (key, json.dumps(v)))
    return float(v)


def _int(v, key, lo):
    if isinstance(v, bool) or not isinstance(v, int) or v < lo:
        raise SceneError("key '%s': expected an integer >= %d, got %s" % (key, lo, json.dumps(v)))
    return v


def _vec(v, n, key):
    if not isinstance(v, list) or len(v) != n:
        raise SceneError("key '%s': expected a list of %d numbers, got %s" % (key, n, json.dumps(v)))
    return [_num(x, "%s[%d]" % (key, i)) for i, x in enumerate(v)]


def _get(d, k, prefix=""):
    if not isinstance(d, dict):
        raise SceneError("key '%s': expected an object" % (prefix.rstrip(".") or "<top level>"))
    if k not in d:
        raise SceneError("missing key '%s%s'" % (prefix, k))
    return d[k]


def _str(v, key):
    if not isinstance(v, str) or not v:
        raise SceneError("key '%s': expected a non-empty string, got %s" % (key, json.dumps(v)))
    return v


def load_scene(path):
    """Parse and check SCENE.json; raises SceneError naming the bad key."""
    try:
        with open(path, "r", encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SceneError("cannot read it: %s" % e)
    try:
        raw = json.loads(text)
    except ValueError as e:
        raise SceneError("not valid JSON: %s" % e)
    s = {}
    s["mesh"] = _str(_get(raw, "mesh"), "mesh")
    if not os.path.isfile(s["mesh"]) or not os.access(s["mesh"], os.R_OK):
        raise SceneError("key 'mesh': cannot read the mesh file %s" % s["mesh"])
    s["array"] = _str(_get(raw, "array"), "array")
    assoc = _get(raw, "association")
    if assoc not in ("point", "cell"):
        raise SceneError("key 'association': expected \"point\" or \"cell\", got %s" % json.dumps(assoc))
    s["association"] = assoc
    s["background"] = _vec(_get(raw, "background"), 3, "background")

    tf = _get(raw, "tf")
    colors = _get(tf, "colors", "tf.")
    if not isinstance(colors, list) or not colors:
        raise SceneError("key 'tf.colors': expected a non-empty list of [s, r, g, b]")
    s["colors"] = [_vec(c, 4, "tf.colors[%d]" % i) for i, c in enumerate(colors)]
    opacity = _get(tf, "opacity", "tf.")
    if not isinstance(opacity, list) or not opacity:
        raise SceneError("key 'tf.opacity': expected a non-empty list of [s, a]")
    s["opacity"] = [_vec(o, 2, "tf.opacity[%d]" % i) for i, o in enumerate(opacity)]
    u = _num(_get(tf, "unit_distance", "tf."), "tf.unit_distance")
    if u <= 0:
        raise SceneError("key 'tf.unit_distance': expected a positive number, got %s" % u)
    s["unit_distance"] = u

    mappers = _get(raw, "mappers")
    if not isinstance(mappers, list):
        raise SceneError("key 'mappers': expected a list of names from %s" % ", ".join(MAPPERS))
    for i, m in enumerate(mappers):
        if m not in MAPPERS:
            raise SceneError("key 'mappers[%d]': unknown mapper %s (known: %s)"
                             % (i, json.dumps(m), ", ".join(MAPPERS)))
    s["mappers"] = mappers
    s["warmup"] = _int(_get(raw, "warmup"), "warmup", 0)
    s["repeats"] = _int(_get(raw, "repeats"), "repeats", 1)
    s["out"] = _str(_get(raw, "out"), "out")
    if not os.path.isdir(s["out"]) or not os.access(s["out"], os.W_OK):
        raise SceneError("key 'out': %s is not a writable folder" % s["out"])
    s["out"] = os.path.abspath(s["out"])
    t = raw.get("timeout_s") if isinstance(raw, dict) else None
    s["timeout_s"] = None if t is None else _num(t, "timeout_s")

    frames = _get(raw, "frames")
    if not isinstance(frames, list) or not frames:
        raise SceneError("key 'frames': expected a non-empty list")
    s["frames"] = []
    seen = set()
    for i, fr in enumerate(frames):
        p = "frames[%d]." % i
        tag = _str(_get(fr, "tag", p), p + "tag")
        if not TAG_RE.match(tag):
            raise SceneError("key '%stag': %s may only hold letters, digits and _ . + -" % (p, json.dumps(tag)))
        if tag in seen:
            raise SceneError("key '%stag': tag %s appears twice" % (p, json.dumps(tag)))
        seen.add(tag)
        cam = _get(fr, "camera", p)
        c = p + "camera."
        ortho = _get(cam, "ortho", c)
        if not isinstance(ortho, bool):
            raise SceneError("key '%sortho': expected true or false, got %s" % (c, json.dumps(ortho)))
        s["frames"].append({
            "tag": tag,
            "width": _int(_get(fr, "width", p), p + "width", 1),
            "height": _int(_get(fr, "height", p), p + "height", 1),
            "position": _vec(_get(cam, "position", c), 3, c + "position"),
            "focal_point": _vec(_get(cam, "focal_point", c), 3, c + "focal_point"),
            "view_up": _vec(_get(cam, "view_up", c), 3, c + "view_up"),
            "view_angle": _num(_get(cam, "view_angle", c), c + "view_angle"),
            "ortho": ortho,
            "parallel_scale": _num(_get(cam, "parallel_scale", c), c + "parallel_scale"),
        })
    return s


def load_scene_or_exit(path):
    try:
        return load_scene(path)
    except SceneError as e:
        log("bad scene file %s: %s" % (path, e))
        sys.exit(EXIT_BAD_SCENE)


def import_vtk_or_exit():
    try:
        import vtk  # noqa: F401
    except Exception as e:  # ImportError, or OSError from a missing shared library
        sys.stderr.write("vtk_bench: this Python (%s) has no vtk module: %s; install it with: %s -m pip install vtk\n"
                         % (sys.executable, e, sys.executable))
        sys.stderr.flush()
        sys.exit(EXIT_NO_VTK)
    return vtk


# ---------------------------------------------------------------------------- parent
def signal_name(num):
    try:
        return signal.Signals(num).name
    except (ValueError, AttributeError):
        return "signal %d" % num


def run_mapper_child(scene_path, scene, mapper):
    """Runs one mapper in a child process, forwards its RESULT lines and reports the
    frames it did not finish."""
    tags = [f["tag"] for f in scene["frames"]]
    cmd = [sys.executable, os.path.abspath(__file__), "--one", mapper, scene_path]
    log("%s: %s" % (mapper, " ".join(cmd)))
    t0 = time.time()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    tail = []  # last stderr lines of the child, for the error message

    def pump_stderr():
        for raw in iter(p.stderr.readline, b""):
            sys.stderr.buffer.write(raw)
            sys.stderr.flush()
            line = ANSI_RE.sub("", raw.decode("utf-8", "replace")).strip()
            # keep VTK's and Python's messages for the error report, not our progress lines
            if line and not line.startswith("vtk_bench: "):
                tail.append(line)
                del tail[:-4]

    th = threading.Thread(target=pump_stderr, daemon=True)
    th.start()
    timer = None
    timed_out = []
    if scene["timeout_s"]:
        def on_timeout():
            timed_out.append(True)
            try:
                p.kill()
            except OSError:
                pass
        timer = threading.Timer(scene["timeout_s"], on_timeout)
        timer.daemon = True
        timer.start()

    done = []  # tags reported, in order
    for raw in iter(p.stdout.readline, b""):
        line = raw.decode("utf-8", "replace").rstrip("\r\n")
        obj = None
        if line.startswith("RESULT "):
            try:
                obj = json.loads(line[len("RESULT "):])
            except ValueError:
                obj = None
        if (isinstance(obj, dict) and obj.get("mapper") == mapper and obj.get("tag") in tags
                and obj["tag"] not in done):
            done.append(obj["tag"])
            emit(obj)
        elif line.strip():
            log("%s: unexpected output: %s" % (mapper, line))
    rc = p.wait()
    if timer is not None:
        timer.cancel()
    th.join(timeout=5)

    missing = [t for t in tags if t not in done]
    if rc != 0 or missing:
        log("%s: child exited with status %d after %.1f s" % (mapper, rc, time.time() - t0))
    if not missing:
        return
    if timed_out:
        what = "was killed after running %g s (timeout_s)" % scene["timeout_s"]
    elif rc < 0:
        what = "crashed (killed by %s, signal %d)" % (signal_name(-rc), -rc)
    else:
        what = "exited with status %d" % rc
    why = ""
    if tail:
        why = "; its last messages: " + " | ".join(tail[-2:])[:400]
    for i, t in enumerate(missing):
        if i == 0:
            msg = "the mapper's process %s before finishing this frame%s" % (what, why)
        else:
            msg = "not rendered: the mapper's process %s before finishing frame %s" % (what, missing[0])
        emit({"mapper": mapper, "tag": t, "error": msg})


def parent_main(scene_path):
    vtk = import_vtk_or_exit()  # first: without vtk nothing else matters
    scene = load_scene_or_exit(scene_path)
    log("VTK %s (%s), %d mapper(s), %d frame(s)" % (vtk.vtkVersion.GetVTKVersion(), sys.executable,
                                                  len(scene["mappers"]), len(scene["frames"])))
    scene_path = os.path.abspath(scene_path)
    for m in scene["mappers"]:
        run_mapper_child(scene_path, scene, m)
    return 0


# ---------------------------------------------------------------------------- child
def peak_rss_mb():
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / (1024.0 * 1024.0) if sys.platform == "darwin" else r / 1024.0


class VtkErrors:
    """Collects VTK error messages of one object (instead of only printing them)."""

    def __init__(self, obj):
        self.msgs = []
        obj.AddObserver("ErrorEvent", self._on)

    def _on(self, caller, event, calldata=None):
        # "ERROR: In file.cxx, line N\nvtkClass (0x...): message" -> "vtkClass: message"
        lines = [l.strip() for l in str(calldata if calldata is not None else event).splitlines() if l.strip()]
        self.msgs.append(re.sub(r" \(0x[0-9a-fA-F]+\)", "", lines[-1] if lines else event))
    _on.CallDataType = "string0"


def split_steps(nodes, what):
    """VTK's transfer functions keep one node per scalar value (a second AddPoint at the
    same value replaces the first), so a step given as two nodes at one value would
    lose a side.  Sort the nodes (stable) and move each repeated value up by a tiny
    epsilon instead."""
    nodes = sorted(nodes, key=lambda n: n[0])
    span = nodes[-1][0] - nodes[0][0]
    eps = max(abs(span), abs(nodes[0][0]), 1.0) * 1e-7
    out = []
    for n in nodes:
        n = list(n)
        if out and n[0] <= out[-1][0]:
            n[0] = out[-1][0] + eps
            log("tf.%s: two nodes at scalar %g; the second one moved to %.9g" % (what, out[-1][0], n[0]))
        out.append(n)
    return out


def make_property(vtk, scene):
    colors = split_steps(scene["colors"], "colors")
    opacity = split_steps(scene["opacity"], "opacity")
    ctf = vtk.vtkColorTransferFunction()
    ctf.SetColorSpaceToRGB()
    for s, r, g, b in colors:
        ctf.AddRGBPoint(s, r, g, b)
    # WORKAROUND (VTK bug): the linear, pre-integration and partial pre-integration
    # integrators take only the FIRST opacity node as a control point and otherwise
    # sample opacity at the colour nodes only.  A colour node (with the unchanged
    # colour) at every opacity node makes them exact; the colour function is the same.
    color_xs = set(c[0] for c in colors)
    xs = sorted(set(o[0] for o in opacity if o[0] not in color_xs))
    pads = [(x, ctf.GetColor(x)) for x in xs]  # read all before adding any
    for x, c in pads:
        ctf.AddRGBPoint(x, c[0], c[1], c[2])
    otf = vtk.vtkPiecewiseFunction()
    for s, a in opacity:
        otf.AddPoint(s, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(scene["unit_distance"])
    prop.ShadeOff()
    prop.SetInterpolationTypeToLinear()
    return prop


def make_mapper(vtk, name):
    if name == "pt":
        return vtk.vtkProjectedTetrahedraMapper()  # factory: vtkOpenGLProjectedTetrahedraMapper
    if name.startswith("raycast-"):
        m = vtk.vtkUnstructuredGridVolumeRayCastMapper()
        integ = {
            "linear": vtk.vtkUnstructuredGridLinearRayIntegrator,
            "partial": vtk.vtkUnstructuredGridPartialPreIntegration,
            "preint": vtk.vtkUnstructuredGridPreIntegration,
            "homog": vtk.vtkUnstructuredGridHomogeneousRayIntegrator,
        }[name[len("raycast-"):]]
        m.SetRayIntegrator(integ())
    elif name == "zsweep":
        m = vtk.vtkUnstructuredGridVolumeZSweepMapper()
    else:
        raise ValueError("unknown mapper " + name)
    m.SetAutoAdjustSampleDistances(0)
    m.SetImageSampleDistance(1.0)
    return m


def set_camera(ren, fr, bounds):
    cam = ren.GetActiveCamera()
    cam.SetPosition(*fr["position"])
    cam.SetFocalPoint(*fr["focal_point"])
    cam.SetViewUp(*fr["view_up"])
    cam.SetViewAngle(fr["view_angle"])
    cam.SetParallelProjection(1 if fr["ortho"] else 0)
    cam.SetParallelScale(fr["parallel_scale"])
    ren.ResetCameraClippingRange(bounds)  # not ResetCamera: that would move the camera


def write_png(vtk, rw, path):
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(rw)
    w2i.ShouldRerenderOff()  # the default would render the scene again
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    w = vtk.vtkPNGWriter()  # writes VTK's bottom-up rows as a top-row-first PNG
    w.SetFileName(path)
    w.SetInputConnection(w2i.GetOutputPort())
    errs = VtkErrors(w)
    w.Write()
    if errs.msgs or not os.path.isfile(path):
        raise RuntimeError("could not write %s: %s" % (path, "; ".join(errs.msgs)))


def die_with_parent():
    """Linux: the child gets SIGKILL when the parent dies (e.g. killed on a timeout)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        ppid = os.getppid()
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != ppid:  # the parent died before prctl
            os._exit(1)
    except Exception:
        pass


def child_main(mapper, scene_path):
    die_with_parent()
    scene = load_scene_or_exit(scene_path)
    vtk = import_vtk_or_exit()
    version = vtk.vtkVersion.GetVTKVersion()
    frames = scene["frames"]
    next_frame = [0]

    def fail_rest(msg):
        for fr in frames[next_frame[0]:]:
            emit({"mapper": mapper, "tag": fr["tag"], "error": msg})
        next_frame[0] = len(frames)

    try:
        # ------------------------------------------------------------------ mesh
        t = time.perf_counter()
        reader = vtk.vtkXMLUnstructuredGridReader()
        rerr = VtkErrors(reader)
        reader.SetFileName(scene["mesh"])
        reader.Update()
        read_s = time.perf_counter() - t
        ug = reader.GetOutput()
        if rerr.msgs or ug is None or ug.GetNumberOfCells() == 0:
            raise RuntimeError("could not read %s as a VTK XML unstructured grid%s"
                               % (scene["mesh"], (": " + rerr.msgs[0][:300]) if rerr.msgs else " (no cells)"))
        data = ug.GetPointData() if scene["association"] == "point" else ug.GetCellData()
        arr = data.GetAbstractArray(scene["array"])
        if arr is None:
            names = [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]
            raise RuntimeError("the mesh has no %s array %s (it has: %s)"
                               % (scene["association"], json.dumps(scene["array"]),
                                  ", ".join(json.dumps(n) for n in names) or "none"))

        tetra_s = 0.0
        tetrahedralised = False
        if mapper in NEEDS_TETRA and not (ug.IsHomogeneous() and ug.GetCellType(0) == vtk.VTK_TETRA):
            t = time.perf_counter()
            f = vtk.vtkDataSetTriangleFilter()
            f.SetInputData(ug)
            f.TetrahedraOnlyOn()
            f.Update()
            ug = f.GetOutput()
            tetra_s = time.perf_counter() - t
            tetrahedralised = True
            log("%s: tetrahedralised in %.3f s: %d tetrahedra" % (mapper, tetra_s, ug.GetNumberOfCells()))
        cells = ug.GetNumberOfCells()
        bounds = ug.GetBounds()

        # ------------------------------------------------------------------ window
        fr0 = frames[0]
        rw = vtk.vtkRenderWindow()
        rw.SetOffScreenRendering(1)
        rw.SetMultiSamples(0)  # default 8x MSAA biases projected tetrahedra
        rw.SetAlphaBitPlanes(0)
        rw.SetSize(fr0["width"], fr0["height"])
        ren = vtk.vtkRenderer()
        ren.SetBackground(*scene["background"])
        rw.AddRenderer(ren)
        # Empty render first: creates the GL context, which is not the mapper's setup.
        t = time.perf_counter()
        rw.Render()
        context_s = time.perf_counter() - t

        vmapper = make_mapper(vtk, mapper)
        vmapper.SetInputData(ug)
        if scene["association"] == "point":
            vmapper.SetScalarModeToUsePointFieldData()
        else:
            vmapper.SetScalarModeToUseCellFieldData()
        vmapper.SelectScalarArray(scene["array"])
        vol = vtk.vtkVolume()
        vol.SetMapper(vmapper)
        vol.SetProperty(make_property(vtk, scene))
        ren.AddVolume(vol)
    except Exception as e:
        fail_rest("setup failed: %s: %s" % (type(e).__name__, e))
        return 0

    # ---------------------------------------------------------------------- frames
    # A plain rw.Render() of an unchanged scene re-runs the whole volume mapper for
    # every mapper here (measured with VTK 9.7.2: repeat times equal the time of a
    # render after vol.Modified() or a camera change), so the repeats are plain
    # rw.Render() calls, without Modified().
    for fr in frames:
        try:
            log("%s %s: %dx%d" % (mapper, fr["tag"], fr["width"], fr["height"]))
            rw.SetSize(fr["width"], fr["height"])
            set_camera(ren, fr, bounds)
            t = time.perf_counter()
            rw.Render()
            first_s = time.perf_counter() - t
            for _ in range(scene["warmup"]):
                rw.Render()
            times = []
            for _ in range(scene["repeats"]):
                t = time.perf_counter()
                rw.Render()
                times.append(time.perf_counter() - t)
            image = os.path.join(scene["out"], "vtk_%s_%s.png" % (mapper, fr["tag"]))
            write_png(vtk, rw, image)
            emit({
                "mapper": mapper,
                "tag": fr["tag"],
                "first_s": first_s,
                "times_s": times,
                "median_s": statistics.median(times),
                "min_s": min(times),
                "max_s": max(times),
                "tetra_s": tetra_s,
                "read_s": read_s,
                "context_s": context_s,
                "cells": cells,
                "tetrahedralised": tetrahedralised,
                "peak_rss_mb": peak_rss_mb(),
                "image": image,
                "vtk_version": version,
            })
        except Exception as e:
            emit({"mapper": mapper, "tag": fr["tag"], "error": "%s: %s" % (type(e).__name__, e)})
        next_frame[0] += 1
    return 0


def main(argv):
    if len(argv) == 4 and argv[1] == "--one":
        if argv[2] not in MAPPERS:
            log("unknown mapper %s" % argv[2])
            return EXIT_BAD_SCENE
        return child_main(argv[2], argv[3])
    if len(argv) != 2 or argv[1].startswith("-"):
        log("usage: %s SCENE.json" % os.path.basename(argv[0]))
        return EXIT_BAD_SCENE
    return parent_main(argv[1])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
