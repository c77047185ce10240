#!/usr/bin/env python3
"""`spindle view` end to end (issue 20), one ctest test per mode:

  viewer_test.py http SPINDLE
      hostile requests (malformed, out-of-range, oversized, binary, wrong mode) each get
      an error status with a reason, are logged on stderr, and leave the program serving
      and accepting good commands; SIGTERM then stops it cleanly (exit 0).
  viewer_test.py controls SPINDLE
      the page's controls over HTTP, as its buttons and mouse send them: pause holds the
      steps, step takes one, slow motion and resume, interpolation off (the frame's flag),
      contact points on and off,
      drop adds bodies, grab + drag lifts a body along the cursor's ray, release lets go.
  viewer_test.py replay SPINDLE
      `spindle view --replay` of a `spindle run --record` file serves its frames (replay
      flag, the recorded poses), seeks and steps; a malformed record is refused (exit 1,
      file:line) before any port opens.
  viewer_test.py browser SPINDLE [--scene NAME] [--screenshot-out PNG]
      headless Chromium loads the page of `spindle view stack` (or NAME), waits for
      frames, and the page's own state (#state, read with --dump-dom) must show the
      scene's body count drawn, a click that shot a ball (the count grew), bodies that moved, and a body
      dragged up by the mouse; a screenshot must not be blank. Exits 77 (ctest SKIP)
      when chromium is not installed, and only then.
"""
import atexit
import json
import math
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
import zlib

SKIP = 77
CHROMIUM = os.environ.get("SPINDLE_CHROMIUM", "chromium")  # another browser binary, or a missing one to see the skip
CHROMIUM_FLAGS = ["--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                  "--window-size=960,540", "--hide-scrollbars"]


RUNNING = []  # views to kill when the test ends early (a failed check, an exception)


@atexit.register
def kill_views():
    for proc in RUNNING:
        if proc.poll() is None:
            proc.kill()


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


class View:
    """A running `spindle view ... --port 0`, its URL read from its first lines."""

    def __init__(self, spindle, *args):
        self.err = tempfile.TemporaryFile()
        # --seconds: a view the test lost track of still ends by itself.
        self.proc = subprocess.Popen([spindle, "view", *args, "--port", "0", "--seconds", "900"],
                                     stdout=subprocess.PIPE, stderr=self.err, text=True)
        RUNNING.append(self.proc)
        self.out = []
        deadline = time.time() + 120  # a loaded machine starts slowly
        while time.time() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            self.out.append(line)
            m = re.search(r"view: (http://127\.0\.0\.1:\d+/)", line)
            if m:
                self.url = m.group(1)
                return
        self.proc.kill()
        fail("spindle view printed no URL:\n" + "".join(self.out) + self.stderr())

    def stderr(self):
        self.err.seek(0)
        return self.err.read().decode(errors="replace")

    def request(self, path, body=None):
        """(status, reply body) of a GET, or of a POST when body is given."""
        req = urllib.request.Request(self.url + path, data=body, method="POST" if body is not None else "GET")
        try:
            with urllib.request.urlopen(req, timeout=30) as reply:
                return reply.status, reply.read()
        except urllib.error.HTTPError as e:
            return e.code, e.read()

    def stop(self):
        """SIGTERM, as Ctrl-C; the program must end cleanly and say so."""
        self.proc.send_signal(signal.SIGTERM)
        try:
            rest, _ = self.proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            fail("spindle view did not stop on SIGTERM")
        self.out.append(rest)
        if self.proc.returncode != 0:
            fail("spindle view exited %d on SIGTERM:\n%s%s" % (self.proc.returncode, "".join(self.out), self.stderr()))
        return "".join(self.out)


def test_http(spindle):
    view = View(spindle, "stack")
    hostile = [
        (b"", 400, "empty command"),
        (b"launch 1 2 3", 400, "unknown command 'launch'"),
        (b"shoot 1 2 3", 400, "takes 6 values, got 3"),
        (b"shoot 0 1 2 0 0 nan", 400, "is not a finite number"),
        (b"shoot 0 1 2 0 0 1e999", 400, "is not a finite number"),
        (b"shoot 0 1 2 0 0 0", 400, "direction has no length"),
        (b"shoot 1e9 0 0 0 0 1", 400, "origin is further than"),
        (b"speed 5", 400, "'speed' must be in 0.01..1"),
        (b"speed -1", 400, "'speed' must be in"),
        (b"interpolate maybe", 400, "takes on or off"),
        (b"seek 3", 400, "is only for a replay"),
        (b"pause\x00\xff", 400, "not printable ASCII"),
        (b"step " + b"9" * 300, 400, "at most 256 allowed"),
        (b"shoot " * 2000, 413, "request body over 4096 bytes"),
    ]
    for body, status, reason in hostile:
        got, reply = view.request("command", body)
        if got != status or reason.encode() not in reply:
            fail("POST %r: expected %d '%s', got %d %r" % (body[:40], status, reason, got, reply[:200]))
    got, reply = view.request("no/such/page")
    if got != 404:
        fail("GET of an unknown path: expected 404, got %d" % got)
    refused = len(hostile) + 1

    # Still serving, and still taking good commands.
    got, frame = view.request("frame")
    if got != 200 or struct.unpack_from("<I", frame)[0] != 0x46565053:
        fail("after the hostile requests GET /frame gave %d %r" % (got, frame[:8]))
    bodies = struct.unpack_from("<I", frame, 8)[0]
    if view.request("command", b"shoot 0 3 15 0 0 -1")[0] != 200:
        fail("a good shot was refused after the hostile requests")
    deadline = time.time() + 60
    while time.time() < deadline:
        frame = view.request("frame")[1]
        if struct.unpack_from("<I", frame, 8)[0] > bodies:
            break
        time.sleep(0.1)
    else:
        fail("the shot ball never appeared in the frames (still %d bodies)" % bodies)

    # The ball's hit on the stack is marked in the frames: a point and a unit normal.
    def hit_mark():
        frame = view.request("frame")[1]
        n, marks = struct.unpack_from("<II", frame, 8)
        return struct.unpack_from("<7f", frame, 40 + 32 * n) if marks else None
    mark = wait_for("a contact mark of the shot's hit", hit_mark)
    if abs(sum(v * v for v in mark[3:6]) - 1) > 1e-3 or not 0 <= mark[6] <= 1.5:
        fail("a contact mark with normal %s and age %s" % (mark[3:6], mark[6]))
    deadline = time.time() + 30
    while time.time() < deadline:  # the stats are published twice a second
        stats = json.loads(view.request("stats")[1])
        if stats["refused"] >= refused:
            break
        time.sleep(0.2)
    if stats["refused"] != refused:
        fail("the program counted %d refused requests, expected %d" % (stats["refused"], refused))

    # A second view on the same port is refused, not let in beside the first.
    port = view.url.rsplit(":", 1)[1].strip("/")
    second = subprocess.run([spindle, "view", "stack", "--port", port, "--seconds", "5"], capture_output=True,
                            text=True, timeout=120)
    if second.returncode != 1 or "cannot listen on 127.0.0.1:" + port not in second.stderr:
        fail("a second view on port %s: expected exit 1 'cannot listen', got %d %r" % (port, second.returncode,
                                                                                      second.stderr))

    out = view.stop()
    log = view.stderr()
    logged = log.count("spindle view: refused ")
    if logged != refused:
        fail("expected %d refused requests logged, found %d:\n%s" % (refused, logged, log))
    if "unknown command 'launch'" not in log:
        fail("the log does not say why 'launch' was refused:\n" + log)
    if "requests refused" not in out:
        fail("no closing line after SIGTERM:\n" + out)
    print("ok: %d hostile requests refused with a reason and logged; the program kept serving" % refused)


def frame_of(view):
    """(flags, simulated seconds, steps, [(x, y, z) per body]) of the newest frame."""
    status, frame = view.request("frame")
    if status != 200 or struct.unpack_from("<I", frame)[0] != 0x46565053:
        fail("GET /frame gave %d %r" % (status, frame[:8]))
    bodies = struct.unpack_from("<I", frame, 8)[0]
    flags = struct.unpack_from("<I", frame, 16)[0]
    seconds, steps = struct.unpack_from("<dd", frame, 24)
    return flags, seconds, steps, [struct.unpack_from("<3f", frame, 40 + 32 * i) for i in range(bodies)]


def contact_marks(view):
    """[(px, py, pz, nx, ny, nz, age) per contact mark] of the newest frame."""
    status, frame = view.request("frame")
    bodies, marks = struct.unpack_from("<II", frame, 8)
    return [struct.unpack_from("<7f", frame, 40 + 32 * bodies + 28 * k) for k in range(marks)]


def command(view, text):
    status, reply = view.request("command", text.encode())
    if status != 200:
        fail("command %r refused: %d %r" % (text, status, reply))


def wait_for(what, ok, seconds=60):
    """Polls ok() until it holds; a slow machine gets a generous deadline, never a timing assert."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        value = ok()
        if value:
            return value
        time.sleep(0.1)
    fail("waited %d s for %s" % (seconds, what))


def test_controls(spindle):
    view = View(spindle, "pile")
    stats = lambda: json.loads(view.request("stats")[1])

    command(view, "pause")
    wait_for("the paused mode", lambda: stats()["mode"] == "paused")
    held = frame_of(view)[2]
    time.sleep(1)
    if frame_of(view)[2] != held:
        fail("steps went on while paused: %d then %d" % (held, frame_of(view)[2]))
    command(view, "step")
    wait_for("one step", lambda: frame_of(view)[2] == held + 1)
    time.sleep(0.5)
    if frame_of(view)[2] != held + 1:
        fail("a step while paused took more than one step")

    command(view, "speed 0.25")
    command(view, "resume")
    wait_for("slow motion", lambda: stats()["mode"] == "slow")
    wait_for("steps in slow motion", lambda: frame_of(view)[2] > held + 5)
    command(view, "speed 1")
    wait_for("running again", lambda: stats()["mode"] == "running")

    command(view, "interpolate off")
    wait_for("raw frames", lambda: frame_of(view)[0] & 2 == 0)
    command(view, "interpolate on")
    wait_for("interpolated frames", lambda: frame_of(view)[0] & 2 == 2)

    # Touching points on demand: none while off, the resting pile's points with unit normals
    # while on, none again once off. `spindle view` makes every scene body report its hits, and
    # a hit stays marked for a second: a pile still settling (a loaded machine reaches this line
    # sooner in simulated time) shows hit marks without any point. So: no point counted while
    # off, and the marks fade (the resting pile's points, were they sent, would not).
    if stats()["contact_points"] != 0:
        fail("contact points counted before the page asked for them")
    wait_for("the pile's hit marks to fade (points sent while off would not)", lambda: not contact_marks(view))
    command(view, "contacts on")
    marks = wait_for("touching points in the frames", lambda: contact_marks(view))
    for m in marks:
        if abs(math.sqrt(m[3] ** 2 + m[4] ** 2 + m[5] ** 2) - 1) > 1e-3:
            fail("a contact point's normal is not unit length: %r" % (m,))
    wait_for("the points counted in the stats", lambda: stats()["contact_points"] > 0)
    command(view, "contacts off")
    wait_for("no touching points", lambda: not contact_marks(view) and stats()["contact_points"] == 0)

    bodies = len(frame_of(view)[3])
    command(view, "drop")
    wait_for("the dropped bodies", lambda: len(frame_of(view)[3]) == bodies + 8)
    for _ in range(59):  # 480 crates asked for: the oldest go beyond 400, however many are asked for
        command(view, "drop")
    wait_for("the cap on dropped bodies", lambda: len(frame_of(view)[3]) == bodies + 400)
    time.sleep(1)
    if len(frame_of(view)[3]) != bodies + 400:
        fail("dropped bodies beyond the cap of 400: %d" % (len(frame_of(view)[3]) - bodies))

    # Grab a scene body from 5 m above it, then move the ray 3 m up: the body must follow.
    scene = json.loads(view.request("scene")[1])
    moving = [i for i, (shape, is_moving, projectile, sensor) in enumerate(scene["bodies"])
              if is_moving and not projectile and not sensor]
    command(view, "pause")  # hold everything still while choosing, so the ray meets the body where it is
    wait_for("the paused mode", lambda: stats()["mode"] == "paused")
    positions = frame_of(view)[3]
    body = max(moving, key=lambda i: positions[i][1])  # the highest: nothing above it
    x, y, z = positions[body]
    command(view, "grab %f %f %f 0 -1 0" % (x, y + 5, z))
    wait_for("the grab", lambda: stats()["grabbing"])
    command(view, "drag %f %f %f 0 -1 0" % (x, y + 8, z))
    command(view, "resume")
    wait_for("the body lifted toward the cursor", lambda: frame_of(view)[3][body][1] > y + 2)
    command(view, "release")
    wait_for("the release", lambda: not stats()["grabbing"])
    view.stop()
    print("ok: pause, step, slow motion, interpolation, contact points, drop and drag act as the page asks")


def test_replay(spindle):
    record = os.path.join(tempfile.mkdtemp(), "stack.csv")
    run = subprocess.run([spindle, "run", "stack", "--seconds", "1", "--record", record], capture_output=True,
                         text=True, timeout=300)
    if run.returncode != 0:
        fail("spindle run --record failed:\n" + run.stdout + run.stderr)
    rows = open(record).read().splitlines()
    last = rows[-1].split(",")
    recorded_top = [float(v) for v in last[3:6]]  # the last frame's last body: the top cube
    duration = float(last[1]) - float(rows[1].split(",")[1])

    view = View(spindle, "--replay", record, "stack")
    flags, _, _, positions = frame_of(view)
    if not flags & 4:
        fail("replay frames carry no replay flag (flags %d)" % flags)
    if len(positions) != 21:
        fail("the replay has %d bodies, stack has 21" % len(positions))
    if view.request("command", b"shoot 0 1 10 0 0 -1")[0] != 400:
        fail("a replay accepted a shot")
    command(view, "seek %f" % (duration + 1))  # past the end: the last frame
    wait_for("the last frame", lambda: frame_of(view)[1] >= duration - 1e-6)
    top = frame_of(view)[3][20]
    if max(abs(a - b) for a, b in zip(top, recorded_top)) > 1e-4:
        fail("the last replayed frame puts the top cube at %s, the record at %s" % (top, recorded_top))
    command(view, "seek 0")
    command(view, "pause")
    wait_for("the start, paused", lambda: frame_of(view)[1] == 0 and frame_of(view)[0] & 1)
    command(view, "step")
    wait_for("the second frame", lambda: frame_of(view)[2] == 1)
    view.stop()

    bad = os.path.join(tempfile.mkdtemp(), "bad.csv")
    with open(bad, "w") as f:
        f.write(rows[0] + "\n" + rows[1] + "\n0,0,1,oops\n")
    result = subprocess.run([spindle, "view", "--replay", bad, "stack", "--port", "0"], capture_output=True,
                            text=True, timeout=120)
    if result.returncode != 1 or bad + ":3: expected 13 comma-separated numbers" not in result.stderr:
        fail("a malformed record: expected exit 1 naming %s:3, got %d %r" % (bad, result.returncode, result.stderr))
    if "view: http" in result.stdout:
        fail("a malformed record opened the port first")
    print("ok: the replay serves, seeks and steps through the record; a malformed record is refused")


def read_png(path):
    """(width, height, rows of RGB(A) bytes) of an 8-bit RGB or RGBA PNG."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(path + " is not a PNG")
    pos, idat, width, height, channels = 8, b"", 0, 0, 0
    while pos < len(data):
        length, kind = struct.unpack_from(">I4s", data, pos)
        chunk = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack_from(">IIBB", chunk)
            if depth != 8 or color not in (2, 6):
                fail("%s: expected 8-bit RGB or RGBA, got depth %d color type %d" % (path, depth, color))
            channels = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            left = row[i - channels] if i >= channels else 0
            up = previous[i]
            corner = previous[i - channels] if i >= channels else 0
            if kind == 1:
                row[i] = (row[i] + left) & 255
            elif kind == 2:
                row[i] = (row[i] + up) & 255
            elif kind == 3:
                row[i] = (row[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                row[i] = (row[i] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        rows.append(row)
        previous = row
    return width, height, channels, rows


def chromium(url, *extra, timeout=600):
    return subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, *extra, url], capture_output=True, text=True, timeout=timeout)


def test_browser(spindle, scene, screenshot_out):
    if not shutil.which(CHROMIUM):
        print("chromium is not installed (scripts/setup.sh --test installs it): skipped")
        sys.exit(SKIP)
    view = View(spindle, scene)
    scene_line = next((l for l in view.out if l.startswith("scene ")), "")
    m = re.search(r"(\d+) dynamic \+ (\d+) other bodies", scene_line)
    if not m:
        fail("no scene line in the program's output:\n" + "".join(view.out))
    scene_bodies = int(m.group(1)) + int(m.group(2))

    # The screenshot first, while the scene is young and moving (no shot: the page's own
    # test below counts the bodies before its shot).
    shot = os.path.join(tempfile.mkdtemp(), "viewer.png")
    chromium(view.url, "--virtual-time-budget=5000", "--screenshot=" + shot)
    if not os.path.exists(shot):
        fail("chromium wrote no screenshot")
    width, height, channels, rows = read_png(shot)
    # Right of the panel only: the 3D view must not be one colour (without WebGL the page
    # shows its background alone), and more than a sliver of it must differ from that.
    counts = {}
    for y in range(0, height, 2):
        row = rows[y]
        for x in range(width // 3, width, 2):
            colour = bytes(row[x * channels:x * channels + 3])
            counts[colour] = counts.get(colour, 0) + 1
    drawn = 1 - max(counts.values()) / sum(counts.values())
    if len(counts) < 8 or drawn < 0.05:
        fail("the screenshot's 3D view is blank: %d colours, %.1f%% not background" % (len(counts), 100 * drawn))
    if screenshot_out:
        shutil.copyfile(shot, screenshot_out)

    # Virtual time runs only while the page waits on no request; the frames keep it
    # waiting often, so 20 s of it is a minute or so of wall time on a slow machine.
    dom = chromium(view.url + "?test=shoot", "--virtual-time-budget=20000", "--dump-dom").stdout
    m = re.search(r'<pre id="state">([^<]*)</pre>', dom)
    if not m:
        fail("no #state in the page chromium dumped:\n" + dom[:2000])
    state = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    print("page state:", json.dumps(state))
    if state["frames"] < 20:
        fail("the page drew %d frames, expected at least 20" % state["frames"])
    if state.get("bodiesBeforeShot") != scene_bodies:
        fail("the page drew %s bodies before the shot; scene %s has %d" % (state.get("bodiesBeforeShot"), scene,
                                                                            scene_bodies))
    if not state["shotGrew"] or state["drawnBodies"] <= scene_bodies:
        fail("the shot did not add a body: %d drawn, scene has %d" % (state["drawnBodies"], scene_bodies))
    if not state["moved"] > 0.5:
        fail("no body moved as far as the shot ball flies (furthest %.4f m)" % state["moved"])
    if not state.get("dragLifted", 0) > 0.3:
        fail("dragging the highest body up did not lift it (rose %s m)" % state.get("dragLifted"))
    if state["lastError"]:
        fail("the page reported an error: " + state["lastError"])

    view.stop()
    print("ok: %d frames, %d bodies drawn of %d, moved %.2f m; screenshot %dx%d with %d colours" %
          (state["frames"], state["drawnBodies"], scene_bodies, state["moved"], width, height, len(counts)))


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in ("http", "controls", "replay", "browser"):
        print("usage: viewer_test.py http|controls|replay|browser SPINDLE [--scene NAME] [--screenshot-out PNG]",
              file=sys.stderr)
        sys.exit(2)
    if sys.argv[1] == "http":
        test_http(sys.argv[2])
    elif sys.argv[1] == "controls":
        test_controls(sys.argv[2])
    elif sys.argv[1] == "replay":
        test_replay(sys.argv[2])
    else:
        def option(name, default):
            return sys.argv[sys.argv.index(name) + 1] if name in sys.argv[:-1] else default
        test_browser(sys.argv[2], option("--scene", "stack"), option("--screenshot-out", None))


if __name__ == "__main__":
    main()
