"""Tests of sweetspot_client against the real sweetspot-server (no mocks).

    python3 clients/python/test_sweetspot_client.py --server build/server/sweetspot-server
    SWEETSPOT_SERVER=build/server/sweetspot-server python3 -m unittest test_sweetspot_client

Each server is started on 127.0.0.1 with an ephemeral port (``--port 0``, the port read from
its "listening on" line) and ``--jobs-db none``, as tests/server/server_process.hpp does. The
client's answers are compared with the server's direct answer to the same request (a plain
http.client request), timings left out.
"""

import contextlib
import http.client
import io
import json
import os
import re
import select
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from sweetspot_client import ENDPOINTS, Client, SweetspotError, statcast_launches  # noqa: E402

SERVER_BINARY = os.environ.get("SWEETSPOT_SERVER", "")
TOKEN = "python-client-test-token-7f3a9c"

# A sweep slow enough to watch as a job (the bending modes of 20,000 different bats, ~1 ms each
# on one thread): cancelled long before its end.
SLOW_SWEEP = {
    "bat": {"three_segment": {"length_in": 34, "handle_diameter_in": 1.0,
                              "barrel_diameter_in": 2.5, "taper_start_in": 11,
                              "taper_end_in": 21}, "material": "ash"},
    "parameters": [{"path": "three_segment.taper_start_in", "min": 8, "max": 14, "count": 200},
                   {"path": "three_segment.taper_end_in", "min": 18, "max": 24, "count": 100}],
    "outputs": ["vibration_node"],
    "format": "ndjson",
}


class ServerProcess:
    """The real sweetspot-server on 127.0.0.1, an ephemeral port; stopped with SIGTERM."""

    def __init__(self, args=(), env=None):
        if not SERVER_BINARY or not os.access(SERVER_BINARY, os.X_OK):
            raise unittest.SkipTest("no server binary: pass --server PATH or SWEETSPOT_SERVER")
        environment = dict(os.environ)
        environment.pop("SWEETSPOT_AUTH_TOKEN", None)
        environment.update(env or {})
        self.folder = tempfile.TemporaryDirectory(prefix="sweetspot-py-")
        self.process = subprocess.Popen(
            [SERVER_BINARY, "--host", "127.0.0.1", "--port", "0", "--jobs-db", "none",
             "--no-access-log"] + list(args),
            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, cwd=self.folder.name,
            env=environment)
        self.log = []
        self.port = None
        self._reader = None
        deadline = time.monotonic() + 20
        marker = b"listening on 127.0.0.1:"
        while time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line:
                break
            self.log.append(line)
            if marker in line:
                digits = line.split(marker, 1)[1]
                self.port = int(digits[:len(digits) - len(digits.lstrip(b"0123456789"))])
                break
        if self.port is None:
            self.stop()
            raise RuntimeError("the server did not start: %r" % b"".join(self.log))
        # Keep reading its stderr, so a chatty server never blocks on a full pipe.
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        self.url = "http://127.0.0.1:%d" % self.port

    def _drain(self):
        for line in self.process.stderr:
            self.log.append(line)

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        if self._reader is not None:
            self._reader.join(timeout=5)
        self.process.stderr.close()
        self.folder.cleanup()


def direct(server, method, path, body=None, token=TOKEN):
    """The server's own answer, by a plain http.client request: (status, parsed body)."""
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=60)
    headers = {"Content-Type": "application/json"}
    if token:
        headers["Authorization"] = "Bearer " + token
    connection.request(method, path, None if body is None else json.dumps(body), headers)
    response = connection.getresponse()
    data = response.read()
    connection.close()
    content_type = response.getheader("Content-Type", "")
    if "json" in content_type and "ndjson" not in content_type:
        return response.status, json.loads(data)
    return response.status, data.decode()


VOLATILE = {"timing_s", "solve_time_s", "time_s", "timings", "cache_hit", "created_s",
            "started_s", "finished_s", "expires_in_s", "created_at", "started_at",
            "finished_at"}


def steady(value):
    """``value`` without the keys that change from one run to the next (timings, caches)."""
    if isinstance(value, dict):
        return {k: steady(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [steady(v) for v in value]
    return value


MAIN = None


def setUpModule():
    global MAIN
    MAIN = ServerProcess(env={"SWEETSPOT_AUTH_TOKEN": TOKEN})


def tearDownModule():
    if MAIN is not None:
        MAIN.stop()


class EndpointsTest(unittest.TestCase):
    """Every endpoint once through the client, equal to the server's direct answer."""

    def setUp(self):
        self.client = Client(MAIN.url, token=TOKEN, timeout_s=60)

    def same(self, answer, path, body=None, method=None):
        status, expected = direct(MAIN, method or ("GET" if body is None else "POST"), path,
                                  body)
        self.assertLess(status, 300, expected)
        self.assertEqual(steady(answer), steady(expected))

    def test_get_endpoints(self):
        self.assertEqual(self.client.health(), {"status": "ok"})
        for method, path in [(self.client.version, "/v1/version"),
                             (self.client.materials, "/v1/materials"),
                             (self.client.presets, "/v1/presets"),
                             (self.client.balls, "/v1/balls"),
                             (self.client.speed_vs_error, "/v1/speed-vs-error"),
                             (self.client.openapi, "/openapi.json")]:
            with self.subTest(path=path):
                self.same(method(), path)
        self.assertIn("sweetspot_requests_total", self.client.metrics())
        if "/ready" in self.client.openapi()["paths"]:  # a server with the drain (GET /ready)
            self.same({"status": "ready"}, "/ready")
            self.assertIs(Client(MAIN.url).ready(), True)  # needs no token

    def test_every_openapi_operation_has_a_method(self):
        """The client covers the server's OpenAPI document: a method per operation."""
        operations = {(method.upper(), path)
                      for path, item in self.client.openapi()["paths"].items()
                      for method in item if method in ("get", "post", "put", "delete", "patch")}
        self.assertEqual(operations - set(ENDPOINTS), set(), "operations without a client method")
        for name in ENDPOINTS.values():
            self.assertTrue(callable(getattr(self.client, name, None)), name)

    def test_bat_properties_in_trade_units(self):
        answer = self.client.bat_properties(
            bat={"three_segment": {"length_in": 34, "handle_diameter_in": 1.0,
                                   "barrel_diameter_in": 2.5, "taper_start_in": 11,
                                   "taper_end_in": 21}, "material": "ash"},
            pivot_from_knob_in=6, report_units="imperial")
        self.same(answer, "/v1/bat/properties", {
            "bat": {"three_segment": {"length_m": 34 * 0.0254, "handle_radius_m": 0.5 * 0.0254,
                                      "barrel_radius_m": 1.25 * 0.0254,
                                      "taper_start_m": 11 * 0.0254, "taper_end_m": 21 * 0.0254},
                    "material": "ash"},
            "pivot_from_knob_m": 6 * 0.0254, "report_units": "imperial"})
        self.assertAlmostEqual(answer["length_m"], 0.8636, places=12)
        self.assertAlmostEqual(answer["mass_oz"], answer["mass_kg"] / 0.028349523125, places=9)

    def test_sweet_spot_dict_and_keywords(self):
        request = {"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb"},
                   "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone"]}
        answer = self.client.sweet_spot(request, ball__speed_mph=90,
                                        swing={"bat_speed_mph": 70}, report_units="imperial")
        self.same(answer, "/v1/sweet-spot", {
            "bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90},
            "swing": {"bat_speed_mph": 70}, "report_units": "imperial",
            "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone"]})
        best = answer["max_exit_speed"]
        self.assertAlmostEqual(best["exit_speed_mph"], best["exit_speed_mps"] / 0.44704,
                               places=9)
        self.assertEqual(request["ball"], {"preset": "mlb"}, "the caller's dict is not changed")

    def test_collision(self):
        body = {"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.70, "model": "hertz"}
        self.same(self.client.collision(body), "/v1/collision", body)

    def test_compare(self):
        body = {"baseline": {"preset": "paper-wood"},
                "variants": [{"name": "ash", "bat": {"preset": "paper-wood", "material": "ash"}}]}
        answer = self.client.compare(body)
        self.same(answer, "/v1/compare", body)
        self.assertEqual([row["name"] for row in answer["rows"]], ["baseline", "ash"])

    def test_bat_fit_and_modes(self):
        fit = {"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.95,
                                                            "balance_point_m": 0.60}}
        answer = self.client.bat_fit(fit)
        self.same(answer, "/v1/bat/fit", fit)
        self.assertAlmostEqual(answer["properties"]["mass_kg"], 0.95, places=9)
        modes = {"bat": {"preset": "paper-wood"}, "modes": 2, "shape_samples": 5}
        self.same(self.client.bat_modes(modes), "/v1/bat/modes", modes)
        self.assertEqual(self.client.modes, self.client.bat_modes)

    def test_optimize(self):
        body = {"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95,
                                          "barrel_diameter_in": 2.5, "taper_start_in": 11,
                                          "taper_end_in": 21}, "material": "hard-maple"},
                "ball": {"preset": "mlb", "speed_mph": 90}, "swing": {"bat_speed_mph": 70},
                "variables": [{"scale_paths": ["three_segment.handle_radius_m",
                                               "three_segment.barrel_radius_m"],
                               "name": "girth", "min": 0.9, "max": 1.05},
                              {"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.4}],
                "constraints": {"mass_oz": {"min": 29, "max": 31}, "rules": "mlb-wood"},
                "objective": "max_exit_speed"}
        answer = self.client.optimize(body)
        self.same(answer, "/v1/optimize", body)
        self.assertEqual(answer["summary"]["termination"], "converged")

    def test_frontier_streams_one_row_per_value(self):
        body = {"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90},
                "swing": {"bat_speed_mph": 70},
                "variables": [{"path": "material.density_kg_m3", "min": 500, "max": 800}],
                "frontier": {"constraint": "mass_oz", "values": [30, 31, 32]}}
        rows = self.client.frontier(body)
        designs = list(rows)
        self.assertEqual([d["mass_oz"] for d in designs], [30, 31, 32])
        self.assertEqual([d["summary"]["termination"] for d in designs], ["converged"] * 3)
        self.assertEqual(rows.summary["pareto"], [0, 1, 2])
        # The same designs as the JSON answer.
        answer = self.client.optimize(body)
        self.assertEqual([d["objective_value"] for d in designs],
                         [r["objective_value"] for r in answer["rows"]])
        with self.assertRaises(ValueError):
            self.client.frontier({"bat": {"preset": "wood-34-ash"}})

    def test_explore_json_ndjson_csv_agree(self):
        body = {"bat": {"preset": "paper-wood"},
                "parameters": [{"path": "ball.speed_mph", "min": 50, "max": 100, "count": 6}],
                "outputs": ["max_exit_speed"]}
        answer = self.client.explore(body)
        self.same(answer, "/v1/explore", body)
        stream = self.client.explore_rows(body)
        rows = list(stream)
        self.assertEqual(rows, answer["rows"])
        self.assertEqual(steady(stream.summary), steady(answer["summary"]))
        csv_rows = list(self.client.explore_csv(body))
        self.assertEqual([r["max_exit_speed.exit_speed_mps"] for r in csv_rows],
                         [r["max_exit_speed"]["exit_speed_mps"] for r in rows])
        self.assertEqual([r["parameters.ball.speed_mph"] for r in csv_rows],
                         [50, 60, 70, 80, 90, 100])
        status, text = direct(MAIN, "POST", "/v1/explore", dict(body, format="csv"))
        self.assertEqual(len(text.splitlines()), len(csv_rows) + 1)

    def test_flight_when_the_server_has_it(self):
        if "/v1/flight" not in self.client.openapi()["paths"]:
            self.skipTest("this server has no /v1/flight")
        body = {"launch": {"exit_speed_mph": 103, "launch_angle_deg": 27.5,
                           "backspin_rpm": 2500, "sidespin_rpm": 0}}
        self.same(self.client.flight(body), "/v1/flight", body)
        statcast = [{"launch_speed": "103.0", "launch_angle": "27.5", "hc_x": "125.42",
                     "hc_y": "60", "stand": "R"},
                    {"launch_speed": "", "launch_angle": "", "stand": "L"},  # not batted
                    {"launch_speed": "95.1", "launch_angle": "12", "stand": "L"}]
        launches = list(statcast_launches(statcast))
        self.assertEqual(len(launches), 2)
        flights = list(self.client.flights(launches, chunk=1))
        status, expected = direct(MAIN, "POST", "/v1/flight", {"launches": launches})
        self.assertEqual(status, 200, expected)
        self.assertEqual(steady(flights), steady(expected["flights"]))


class ErrorsTest(unittest.TestCase):
    def setUp(self):
        self.client = Client(MAIN.url, token=TOKEN)

    def test_400_names_the_field(self):
        with self.assertRaises(SweetspotError) as caught:
            self.client.sweet_spot(bat={"preset": "paper-wood"}, ball={"mass_kg": -1})
        error = caught.exception
        self.assertEqual((error.status, error.code, error.field),
                         (400, "InvalidValue", "ball.mass_kg"))
        self.assertIn("ball.mass_kg = -1", error.message)
        with self.assertRaises(SweetspotError) as caught:
            self.client.bat_properties(bat={"three_segment": {
                "lenght_in": 34, "handle_diameter_in": 1, "barrel_diameter_in": 2.5,
                "taper_start_in": 11, "taper_end_in": 21}})
        self.assertEqual(caught.exception.code, "UnknownField")
        self.assertEqual(caught.exception.field, "bat.three_segment.lenght_in")

    def test_422_keeps_the_whole_answer(self):
        with self.assertRaises(SweetspotError) as caught:
            self.client.bat_fit(bat={"preset": "paper-wood"},
                                targets={"mass_kg": 0.885, "balance_point_m": 0.564})
        error = caught.exception
        self.assertEqual((error.status, error.code, error.field), (422, "Infeasible", "targets"))
        self.assertIn("closest", error.body)

    def test_401_without_or_with_a_wrong_token(self):
        for token in (None, TOKEN + "x"):
            with self.subTest(token=token):
                with self.assertRaises(SweetspotError) as caught:
                    Client(MAIN.url, token=token).presets()
                self.assertEqual((caught.exception.status, caught.exception.code),
                                 (401, "Unauthorized"))
        self.assertEqual(Client(MAIN.url).health(), {"status": "ok"})  # needs no token
        self.assertIn("presets", Client(MAIN.url, token=TOKEN).presets())

    def test_ready_is_false_while_the_server_drains(self):
        if "/ready" not in self.client.openapi()["paths"]:
            self.skipTest("this server has no GET /ready")
        server = ServerProcess(["--drain-s", "2"])
        try:
            client = Client(server.url)
            self.assertIs(client.ready(), True)
            server.process.terminate()  # the drain: still answering, /ready 503
            deadline = time.monotonic() + 1.5
            while client.ready() and time.monotonic() < deadline:
                time.sleep(0.02)
            self.assertIs(client.ready(), False)
            self.assertIn("presets", client.presets())  # still served while it drains
        finally:
            server.stop()

    def test_404_job(self):
        with self.assertRaises(SweetspotError) as caught:
            self.client.job("0123456789abcdef")
        self.assertEqual((caught.exception.status, caught.exception.code), (404, "NotFound"))


def hold_the_only_connection(test, server):
    """Opens the one connection a `--max-connections 1` server admits and returns it once the
    server answers another with 503 (that answer: the SweetspotError of a client without
    retries)."""
    holder = socket.create_connection(("127.0.0.1", server.port))
    deadline = time.monotonic() + 10
    while True:
        try:
            Client(server.url, retries=0).health()
        except SweetspotError as error:
            if error.status == 503:
                return holder, error
            raise
        test.assertLess(time.monotonic(), deadline, "the held connection was never admitted")
        # The server accepts on several threads: a probe accepted at the same moment can take
        # the one slot first, and the holder is then the one refused (503, closed). A holder
        # that the server wrote to was refused: open another (CI caught this under load).
        readable, _, _ = select.select([holder], [], [], 0)
        if readable:
            holder.close()
            holder = socket.create_connection(("127.0.0.1", server.port))
        time.sleep(0.05)


class RetryTest(unittest.TestCase):
    """429 and 503 provoked for real on servers with tiny limits; Retry-After honoured."""

    def test_503_over_the_connection_limit_is_retried_after_retry_after(self):
        # The held connection sends nothing: a first-byte timeout longer than the test, so the
        # server never closes it (at the default 2 s a loaded machine's slow first 503 lost it).
        server = ServerProcess(["--max-connections", "1", "--first-byte-timeout-s", "30"])
        try:
            # retries=0: the 503 itself, with its Retry-After
            holder, refused = hold_the_only_connection(self, server)
            self.assertEqual((refused.status, refused.code), (503, "TooBusy"))
            self.assertEqual(refused.retry_after, 1.0)

            seen = []

            def on_retry(attempt, status, wait_s):
                seen.append((attempt, status, wait_s))
                holder.close()  # free the slot while the client waits

            started = time.monotonic()
            answer = Client(server.url, retries=3, on_retry=on_retry).presets()
            elapsed = time.monotonic() - started
            self.assertIn("presets", answer)
            self.assertEqual(seen, [(1, 503, 1.0)])
            self.assertGreaterEqual(elapsed, 1.0)  # waited as Retry-After said
            self.assertLess(elapsed, 5.0)
        finally:
            server.stop()

    def test_429_full_job_queue_is_retried(self):
        server = ServerProcess(["--job-workers", "1", "--job-queue", "1",
                                "--explore-threads", "1"])
        try:
            client = Client(server.url, retries=0)
            running = client.submit("/v1/explore", SLOW_SWEEP)
            deadline = time.monotonic() + 10
            while running.refresh().state == "queued" and time.monotonic() < deadline:
                time.sleep(0.02)
            self.assertEqual(running.state, "running")
            queued = client.submit("/v1/explore", SLOW_SWEEP)  # the one place in the queue
            with self.assertRaises(SweetspotError) as caught:
                client.submit("/v1/explore", SLOW_SWEEP)
            self.assertEqual((caught.exception.status, caught.exception.code), (429, "TooBusy"))
            self.assertEqual(caught.exception.retry_after, 1.0)

            seen = []

            def on_retry(attempt, status, wait_s):
                seen.append((attempt, status, wait_s))
                if attempt == 1:
                    queued.cancel()  # makes room in the queue while the client waits

            third = Client(server.url, retries=2, on_retry=on_retry).submit(
                "/v1/explore", SLOW_SWEEP)
            self.assertEqual(seen, [(1, 429, 1.0)])
            self.assertEqual(third.state, "queued")
            self.assertEqual(queued.refresh().state, "cancelled")
            third.cancel()
            running.cancel()
        finally:
            server.stop()

    def test_bounded(self):
        """A server that never frees its slot: the client gives up after `retries`."""
        server = ServerProcess(["--max-connections", "1", "--first-byte-timeout-s", "30"])
        try:
            holder, _ = hold_the_only_connection(self, server)
            seen = []
            started = time.monotonic()
            with self.assertRaises(SweetspotError) as caught:
                Client(server.url, retries=2, max_retry_wait_s=0.1,
                       on_retry=lambda *a: seen.append(a)).presets()
            self.assertEqual(caught.exception.status, 503)
            self.assertEqual(seen, [(1, 503, 0.1), (2, 503, 0.1)])
            self.assertLess(time.monotonic() - started, 3.0)
            holder.close()
        finally:
            server.stop()


# Run in a fresh interpreter, so that its peak RSS (ru_maxrss, a high-water mark) is this
# sweep's alone: 10,000 designs streamed as NDJSON and as CSV, counted row by row; then, as the
# control that shows the measure would see them, the same rows held in a list.
STREAM_PROGRAM = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[1])
from sweetspot_client import Client
client = Client(sys.argv[2], token=sys.argv[3])
request = json.loads(sys.argv[4])
def peak_kb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
client.health()
figures = {"peak_before_kb": peak_kb()}
started = time.monotonic()
stream = client.explore_rows(request)
rows = 0
for row in stream:
    if rows == 0:
        figures["first_row_s"] = time.monotonic() - started
    assert row["index"] == rows, (row["index"], rows)
    assert row["feasible"] and row["max_exit_speed"]["exit_speed_mps"] > 0
    rows += 1
figures.update(ndjson_rows=rows, ndjson_bytes=stream.bytes_read,
               designs_total=stream.summary["designs_total"],
               ndjson_s=time.monotonic() - started, peak_after_ndjson_kb=peak_kb())
csv_stream = client.explore_csv(request, columns=["index", "max_exit_speed.exit_speed_mps",
                                                  "properties.mass_kg"])
csv_rows = 0
for row in csv_stream:
    assert row["index"] == csv_rows and row["max_exit_speed.exit_speed_mps"] > 0
    csv_rows += 1
figures.update(csv_rows=csv_rows, csv_bytes=csv_stream.bytes_read,
               peak_after_csv_kb=peak_kb())
held = list(client.explore_rows(request))
figures.update(held_rows=len(held), peak_after_held_kb=peak_kb(),
               total_s=time.monotonic() - started)
print(json.dumps(figures))
"""


class StreamingTest(unittest.TestCase):
    def test_10000_design_sweep_streams_in_bounded_memory(self):
        request = {"bat": {"preset": "paper-wood"},
                   "parameters": [{"path": "ball.speed_mph", "min": 40, "max": 100, "count": 100},
                                  {"path": "cor", "min": 0.4, "max": 0.6, "count": 100}],
                   "outputs": ["properties", "max_exit_speed"]}
        run = subprocess.run(
            [sys.executable, "-c", STREAM_PROGRAM, HERE, MAIN.url, TOKEN, json.dumps(request)],
            capture_output=True, text=True, timeout=120)
        self.assertEqual(run.returncode, 0, run.stderr)
        figures = json.loads(run.stdout)
        print("\nstreaming figures: %s" % json.dumps(figures), file=sys.stderr)
        self.assertEqual(figures["ndjson_rows"], 10000)
        self.assertEqual(figures["designs_total"], 10000)
        self.assertEqual(figures["csv_rows"], 10000)
        streamed_mb = (figures["peak_after_csv_kb"] - figures["peak_before_kb"]) / 1024
        held_mb = (figures["peak_after_held_kb"] - figures["peak_after_csv_kb"]) / 1024
        # Streaming: the peak does not move (rows are read and dropped one by one); the control,
        # the same rows in a list, moves it by tens of MB.
        self.assertLess(streamed_mb, 4, figures)
        self.assertGreater(held_mb, 5 * max(streamed_mb, 2), figures)
        # And the first row came long before the last: read as the server sent it.
        self.assertLess(figures["first_row_s"], figures["ndjson_s"] / 4, figures)


class JobsTest(unittest.TestCase):
    def setUp(self):
        self.client = Client(MAIN.url, token=TOKEN)

    def test_a_job_with_progress_to_its_result(self):
        body = {"bat": {"preset": "paper-wood"},
                "parameters": [{"path": "ball.speed_mph", "min": 50, "max": 100, "count": 5}],
                "outputs": ["max_exit_speed"], "format": "ndjson"}
        seen = []
        job = self.client.submit("explore", body)
        self.assertIn(job.state, ("queued", "running", "done"))
        job.wait(progress=lambda j: seen.append((j.state, j.progress)), poll_s=0.05)
        self.assertEqual(job.state, "done")
        self.assertEqual(seen[-1], ("done", 1.0))
        rows = list(job.result_rows())
        self.assertEqual(rows, list(self.client.explore_rows(body)))
        self.assertIn(job.id, [j["id"] for j in self.client.jobs(state="done")["jobs"]])
        compare = {"baseline": {"preset": "paper-wood"},
                   "variants": [{"name": "ash",
                                 "bat": {"preset": "paper-wood", "material": "ash"}}]}
        self.assertEqual(steady(self.client.run_job("/v1/compare", compare, poll_s=0.05)),
                         steady(self.client.compare(compare)))

    def test_a_job_cancelled_while_it_runs(self):
        seen = []

        def progress(job):
            seen.append((job.state, job.progress))
            if job.state == "running" and job.progress > 0 and not job.info["cancel_requested"]:
                job.cancel()

        job = self.client.submit("/v1/explore", SLOW_SWEEP)
        job.wait(progress=progress, poll_s=0.05, timeout_s=60)
        self.assertEqual(job.state, "cancelled", seen)
        fractions = [p for s, p in seen if s == "running"]
        self.assertTrue(any(0 < p < 1 for p in fractions), seen)
        # docs/api.md: a cancelled sweep answers 409 Cancelled; a server that keeps the rows
        # made before the cancel ends them with an {"error": {"code": "Cancelled"}} line. The
        # client raises either as SweetspotError, code Cancelled.
        with self.assertRaises(SweetspotError) as caught:
            for _ in job.result_rows():
                pass
        self.assertEqual(caught.exception.code, "Cancelled")


class DocumentedPipelineTest(unittest.TestCase):
    def test_the_example_pipeline_runs(self):
        import example_pipeline
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            example_pipeline.main(MAIN.url, TOKEN)
        text = out.getvalue()
        self.assertIn("sweep: 10000 designs", text)
        self.assertEqual(text.count("(converged)"), 4, text)

    def test_the_documented_python_compiles(self):
        root = os.path.dirname(os.path.dirname(HERE))
        blocks = 0
        for name in ("README.md", os.path.join("docs", "api.md")):
            with open(os.path.join(root, name), encoding="utf-8") as document:
                text = document.read()
            for block in re.findall(r"```python\n(.*?)```", text, re.S):
                if "sweetspot_client" in block:
                    compile(block, name, "exec")
                    blocks += 1
        self.assertGreaterEqual(blocks, 2)


if __name__ == "__main__":
    if "--server" in sys.argv:
        at = sys.argv.index("--server")
        SERVER_BINARY = os.path.abspath(sys.argv[at + 1])
        del sys.argv[at:at + 2]
    unittest.main()
