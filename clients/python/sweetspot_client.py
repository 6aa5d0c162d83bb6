"""A Python client for the sweetspot HTTP API (standard library only, Python 3.9+).

    from sweetspot_client import Client, SweetspotError

    client = Client("http://127.0.0.1:8080")               # token="..." when the server has one
    answer = client.sweet_spot(bat={"preset": "wood-34-ash"},
                               ball={"preset": "mlb", "speed_mph": 90},
                               swing={"bat_speed_mph": 70},
                               outputs=["max_exit_speed", "sweet_zone"],
                               report_units="imperial")
    for row in client.explore_rows({...a sweep...}):       # NDJSON, streamed row by row
        ...

Every endpoint method takes the request as a dict, as keyword arguments, or both (keywords
override the dict's top-level keys; ``ball__speed_mph=90`` sets ``{"ball": {"speed_mph": 90}}``).
Field names are the API's own, SI or trade units (``_in``, ``_oz``, ``_mph``, ``_oz_in2``): the
client never converts a number; the server does (docs/api.md, "The trade's units").

Errors are raised as :class:`SweetspotError` with ``status``, ``code``, ``field`` and
``message`` (the server's error object; ``body`` holds the whole answer, e.g. a 422's
``closest``). 429 and 503 answers are retried up to ``retries`` times, each after the answer's
``Retry-After`` (capped by ``max_retry_wait_s``), as are connections the server refused or
reset before answering.
"""

import csv
import email.utils
import http.client
import json
import time
import urllib.parse
from typing import Any, Callable, Dict, Iterator, List, Optional

__all__ = ["Client", "ENDPOINTS", "Job", "RowStream", "SweetspotError", "statcast_launches"]
__version__ = "0.1.0"

JsonDict = Dict[str, Any]

_TERMINAL_JOB_STATES = ("done", "failed", "cancelled")

# Every operation of the OpenAPI document (docs/openapi.json, GET /openapi.json) and the
# Client method that calls it; the test checks the server's document against this table.
ENDPOINTS = {
    ("GET", "/health"): "health",
    ("GET", "/ready"): "ready",
    ("GET", "/openapi.json"): "openapi",
    ("GET", "/metrics"): "metrics",
    ("GET", "/v1/version"): "version",
    ("GET", "/v1/speed-vs-error"): "speed_vs_error",
    ("GET", "/v1/materials"): "materials",
    ("GET", "/v1/presets"): "presets",
    ("GET", "/v1/balls"): "balls",
    ("POST", "/v1/bat/properties"): "bat_properties",
    ("POST", "/v1/bat/fit"): "bat_fit",
    ("POST", "/v1/bat/modes"): "bat_modes",
    ("POST", "/v1/sweet-spot"): "sweet_spot",
    ("POST", "/v1/collision"): "collision",
    ("POST", "/v1/compare"): "compare",
    ("POST", "/v1/optimize"): "optimize",
    ("POST", "/v1/explore"): "explore",
    ("POST", "/v1/flight"): "flight",
    ("POST", "/v1/jobs"): "submit",
    ("GET", "/v1/jobs"): "jobs",
    ("GET", "/v1/jobs/{id}"): "job",
    ("DELETE", "/v1/jobs/{id}"): "cancel_job",
    ("GET", "/v1/jobs/{id}/result"): "job_result",
}


class SweetspotError(Exception):
    """An error answer of the server (or a transport failure, ``status`` None).

    ``status`` is the HTTP status, ``code`` / ``field`` / ``message`` the server's error object
    (``{"code", "message", "field"}``, docs/api.md "Errors"), ``body`` the whole parsed answer
    (a dict, or the text when it was not JSON), ``retry_after`` the answer's Retry-After in
    seconds (None without one).
    """

    def __init__(self, status: Optional[int], code: Optional[str], message: str,
                 field: Optional[str] = None, body: Any = None,
                 retry_after: Optional[float] = None) -> None:
        super().__init__("%s %s%s: %s" % (status, code, " on " + field if field else "", message))
        self.status = status
        self.code = code
        self.field = field
        self.message = message
        self.body = body
        self.retry_after = retry_after


def _merge(request: Optional[JsonDict], fields: JsonDict) -> JsonDict:
    """The request: a copy of ``request`` with the keyword fields set on it (``a__b=1`` sets
    ``{"a": {"b": 1}}``, merged into an object already there); None values are left out."""
    body: JsonDict = dict(request or {})
    for key, value in fields.items():
        if value is None:
            continue
        parts = key.split("__")
        target = body
        for part in parts[:-1]:
            child = target.get(part)
            child = dict(child) if isinstance(child, dict) else {}
            target[part] = child
            target = child
        target[parts[-1]] = value
    return body


def _retry_after_seconds(value: Optional[str]) -> Optional[float]:
    if value is None:
        return None
    value = value.strip()
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:  # an HTTP-date
        when = email.utils.parsedate_to_datetime(value)
        return max(0.0, when.timestamp() - time.time())
    except (TypeError, ValueError, IndexError, OverflowError):
        return None


def _error_from(status: int, data: bytes, retry_after: Optional[float]) -> SweetspotError:
    text = data.decode("utf-8", "replace")
    try:
        body = json.loads(text)
    except ValueError:
        body = text
    if isinstance(body, dict) and "code" in body:
        return SweetspotError(status, body.get("code"), str(body.get("message", "")),
                              body.get("field"), body, retry_after)
    return SweetspotError(status, None, text.strip() or http.client.responses.get(status, ""),
                          None, body, retry_after)


def _csv_value(text: str) -> Any:
    """A CSV field as the server wrote it: '' is None, true/false booleans, numbers numbers."""
    if text == "":
        return None
    if text == "true":
        return True
    if text == "false":
        return False
    first = text[0]
    if first.isdigit() or first in "-.":
        try:
            return int(text)
        except ValueError:
            try:
                return float(text)
            except ValueError:
                return text
    return text


class RowStream:
    """The rows of a streamed answer (NDJSON or CSV), read line by line from the response as
    they arrive: rows are never held, so a sweep of any size runs in constant memory.

    Iterate it (``for row in stream``) or use it as a context manager; closing it early closes
    the connection, which stops the sweep on the server. For NDJSON, ``summary`` holds the
    final ``{"summary": ...}`` line's object once the rows are read; an ``{"error": ...}`` line
    (a sweep stopped mid-stream: time budget, memory, cancel) raises :class:`SweetspotError`.
    For CSV each row is a dict keyed by the header's column paths, the values converted
    (numbers, booleans, None for an empty field) unless ``convert=False``; ``header`` holds the
    column names. ``bytes_read`` counts the body's bytes so far.
    """

    def __init__(self, connection: http.client.HTTPConnection,
                 response: http.client.HTTPResponse, kind: str, convert: bool = True) -> None:
        self._connection = connection
        self._response = response
        self.kind = kind
        self.convert = convert
        self.summary: Optional[JsonDict] = None
        self.header: Optional[List[str]] = None
        self.rows_read = 0
        self.bytes_read = 0
        self.status = response.status
        self.content_type = response.getheader("Content-Type", "")

    def _lines(self) -> Iterator[bytes]:
        response = self._response
        while True:
            line = response.readline()
            if not line:
                return
            self.bytes_read += len(line)
            yield line

    def __iter__(self) -> Iterator[Any]:
        try:
            if self.kind == "csv":
                yield from self._csv_rows()
            else:
                yield from self._ndjson_rows()
        finally:
            self.close()

    def _ndjson_rows(self) -> Iterator[JsonDict]:
        for line in self._lines():
            if not line.strip():
                continue
            row = json.loads(line)
            if isinstance(row, dict) and len(row) == 1:
                if "summary" in row and isinstance(row["summary"], dict):
                    self.summary = row["summary"]
                    continue
                if "error" in row and isinstance(row["error"], dict):
                    error = row["error"]
                    raise SweetspotError(self.status, error.get("code"),
                                         str(error.get("message", "")), error.get("field"),
                                         error)
            self.rows_read += 1
            yield row

    def _csv_rows(self) -> Iterator[Dict[str, Any]]:
        reader = csv.reader(line.decode("utf-8") for line in self._lines())
        for record in reader:
            if self.header is None:
                self.header = record
                continue
            if self.convert:
                values = [_csv_value(v) for v in record]
            else:
                values = list(record)
            self.rows_read += 1
            yield dict(zip(self.header, values))

    def close(self) -> None:
        if self._connection is not None:
            self._connection.close()
            self._connection = None

    def __enter__(self) -> "RowStream":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


class Job:
    """A job of ``POST /v1/jobs``: ``id``, ``state``, ``progress`` and the rest of the job's
    JSON in ``info`` (refreshed by :meth:`refresh` and :meth:`wait`)."""

    def __init__(self, client: "Client", info: JsonDict) -> None:
        self.client = client
        self.info = info

    @property
    def id(self) -> str:
        return self.info["id"]

    @property
    def state(self) -> str:
        return self.info["state"]

    @property
    def progress(self) -> float:
        return float(self.info.get("progress") or 0.0)

    @property
    def finished(self) -> bool:
        return self.state in _TERMINAL_JOB_STATES

    def refresh(self) -> "Job":
        self.info = self.client.job(self.id)
        return self

    def wait(self, progress: Optional[Callable[["Job"], Any]] = None, poll_s: float = 0.2,
             timeout_s: Optional[float] = None) -> "Job":
        """Polls until the job is done, failed or cancelled and returns it; ``progress(job)`` is
        called after every poll (it may call ``job.cancel()``). Raises SweetspotError (status
        None, code ``Timeout``) when ``timeout_s`` passes first; the job keeps running."""
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while True:
            self.refresh()
            if progress is not None:
                progress(self)
            if self.finished:
                return self
            if deadline is not None and time.monotonic() >= deadline:
                raise SweetspotError(None, "Timeout", "job %s still %s after %.3g s"
                                     % (self.id, self.state, timeout_s))
            time.sleep(poll_s)

    def cancel(self) -> JsonDict:
        """``DELETE /v1/jobs/{id}``: a queued job is cancelled, a running one stops at its next
        cancel check (the answer's ``cancel_requested``), a finished one is deleted."""
        self.info = self.client.cancel_job(self.id)
        return self.info

    def result(self) -> Any:
        """The inner request's answer (JSON, or the text of a CSV/NDJSON sweep); its error
        answer, or 409 NotReady / Cancelled, raised as SweetspotError."""
        return self.client.job_result(self.id)

    def result_rows(self, convert: bool = True) -> RowStream:
        """A finished explore job's NDJSON or CSV result, streamed row by row."""
        return self.client.stream("GET", "/v1/jobs/%s/result" % self.id, convert=convert)

    def __repr__(self) -> str:
        return "Job(id=%r, state=%r, progress=%.3f)" % (self.id, self.state, self.progress)


class Client:
    """A client of one sweetspot server.

    ``base_url``: e.g. ``http://127.0.0.1:8080`` (a path prefix is kept: behind a proxy at
    ``https://host/sweetspot``). ``token``: sent as ``Authorization: Bearer <token>`` (the
    server's ``SWEETSPOT_AUTH_TOKEN``). ``timeout_s``: the socket timeout of every connect and
    read (a streamed sweep may take longer in total; each read waits at most this).
    ``retries``: how many times a 429 or 503 answer (or a connection refused or reset before an
    answer) is retried; each wait is the answer's ``Retry-After`` (else ``retry_wait_s``,
    doubling), at most ``max_retry_wait_s``. ``on_retry(attempt, status, wait_s)`` is called
    before each wait (``status`` None for a connection error).
    """

    def __init__(self, base_url: str = "http://127.0.0.1:8080", token: Optional[str] = None,
                 timeout_s: float = 120.0, retries: int = 3, retry_wait_s: float = 0.5,
                 max_retry_wait_s: float = 30.0,
                 on_retry: Optional[Callable[[int, Optional[int], float], Any]] = None) -> None:
        parts = urllib.parse.urlsplit(base_url)
        if parts.scheme not in ("http", "https") or not parts.hostname:
            raise ValueError("base_url must be http://host[:port][/prefix] or https://...: %r"
                             % base_url)
        self.base_url = base_url
        self._scheme = parts.scheme
        self._host = parts.hostname
        self._port = parts.port
        self._prefix = parts.path.rstrip("/")
        self.token = token
        self.timeout_s = timeout_s
        self.retries = max(0, int(retries))
        self.retry_wait_s = retry_wait_s
        self.max_retry_wait_s = max_retry_wait_s
        self.on_retry = on_retry

    # ---- transport -----------------------------------------------------------------------

    def _connect(self) -> http.client.HTTPConnection:
        if self._scheme == "https":
            return http.client.HTTPSConnection(self._host, self._port, timeout=self.timeout_s)
        return http.client.HTTPConnection(self._host, self._port, timeout=self.timeout_s)

    def _send(self, method: str, path: str, body: Any, query: Optional[JsonDict],
               retries: Optional[int] = None):
        """Sends one request, retrying 429/503 and refused connections (``retries``, default
        the client's); returns the open connection and its response (status < 400), or raises
        SweetspotError."""
        retries = self.retries if retries is None else retries
        url = self._prefix + path
        if query:
            pairs = [(k, v) for k, v in query.items() if v is not None]
            if pairs:
                url += "?" + urllib.parse.urlencode(pairs)
        data = None
        headers = {"Accept": "application/json, application/x-ndjson, text/csv"}
        if body is not None:
            data = json.dumps(body, allow_nan=False).encode("utf-8")
            headers["Content-Type"] = "application/json"
        if self.token is not None:
            headers["Authorization"] = "Bearer " + self.token
        attempt = 0
        backoff = self.retry_wait_s
        while True:
            connection = self._connect()
            status = None
            retry_after = None
            try:
                try:
                    connection.request(method, url, body=data, headers=headers)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the server may have answered (503 over its limits) and closed: read it
                response = connection.getresponse()
                status = response.status
                if status < 400:
                    return connection, response
                retry_after = _retry_after_seconds(response.getheader("Retry-After"))
                error = _error_from(status, response.read(), retry_after)
                connection.close()
                if status not in (429, 503) or attempt >= retries:
                    raise error
            except (ConnectionRefusedError, ConnectionResetError, BrokenPipeError,
                    http.client.RemoteDisconnected, http.client.BadStatusLine) as exc:
                connection.close()
                if attempt >= retries:
                    raise SweetspotError(None, "ConnectionError", "%s %s: %s"
                                         % (method, url, exc)) from exc
            except OSError as exc:  # a timeout, an unreachable host
                connection.close()
                raise SweetspotError(None, "ConnectionError", "%s %s: %s"
                                     % (method, url, exc)) from exc
            attempt += 1
            if retry_after is not None:
                wait = retry_after
            else:
                wait = backoff
                backoff *= 2
            wait = min(wait, self.max_retry_wait_s)
            if self.on_retry is not None:
                self.on_retry(attempt, status, wait)
            time.sleep(wait)

    def request(self, method: str, path: str, body: Any = None,
                query: Optional[JsonDict] = None) -> Any:
        """One request; the answer parsed (JSON → dict, anything else → str)."""
        connection, response = self._send(method, path, body, query)
        try:
            data = response.read()
        finally:
            connection.close()
        content_type = response.getheader("Content-Type", "")
        if "json" in content_type and "ndjson" not in content_type:
            return json.loads(data.decode("utf-8"))
        return data.decode("utf-8")

    def stream(self, method: str, path: str, body: Any = None, convert: bool = True,
               kind: Optional[str] = None) -> RowStream:
        """A request whose answer is NDJSON or CSV rows, returned as a :class:`RowStream`."""
        connection, response = self._send(method, path, body, None)
        if kind is None:
            content_type = response.getheader("Content-Type", "")
            kind = "csv" if "csv" in content_type else "ndjson"
        return RowStream(connection, response, kind, convert)

    def _post(self, path: str, request: Optional[JsonDict], fields: JsonDict) -> Any:
        return self.request("POST", path, _merge(request, fields))

    # ---- GET endpoints -------------------------------------------------------------------

    def health(self) -> JsonDict:
        """``GET /health``: ``{"status": "ok"}`` (no token needed)."""
        return self.request("GET", "/health")

    def ready(self) -> bool:
        """``GET /ready``: True while the server takes new requests, False while it drains
        before stopping (503, not retried: a readiness check says what is, now)."""
        try:
            connection, response = self._send("GET", "/ready", None, None, retries=0)
        except SweetspotError as error:
            if error.status == 503:
                return False
            raise
        response.read()
        connection.close()
        return True

    def openapi(self) -> JsonDict:
        """``GET /openapi.json``: the OpenAPI 3 document."""
        return self.request("GET", "/openapi.json")

    def metrics(self) -> str:
        """``GET /metrics``: Prometheus text."""
        return self.request("GET", "/metrics")

    def version(self) -> JsonDict:
        """``GET /v1/version``."""
        return self.request("GET", "/v1/version")

    def speed_vs_error(self) -> JsonDict:
        """``GET /v1/speed-vs-error``: every model's cost against its error."""
        return self.request("GET", "/v1/speed-vs-error")

    def materials(self) -> JsonDict:
        """``GET /v1/materials``: ``{"materials": [...]}``."""
        return self.request("GET", "/v1/materials")

    def presets(self) -> JsonDict:
        """``GET /v1/presets``: ``{"presets": [...]}``."""
        return self.request("GET", "/v1/presets")

    def balls(self) -> JsonDict:
        """``GET /v1/balls``: ``{"balls": [...]}``."""
        return self.request("GET", "/v1/balls")

    # ---- computing endpoints (request dict and/or keyword fields) ------------------------

    def bat_properties(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/bat/properties``: mass, balance point, moments of inertia."""
        return self._post("/v1/bat/properties", request, fields)

    def bat_fit(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/bat/fit``: unknown dimensions from target mass / balance point (422
        ``Infeasible`` raised with the ``closest`` bat in ``error.body``)."""
        return self._post("/v1/bat/fit", request, fields)

    def bat_modes(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/bat/modes``: the free-free bending modes."""
        return self._post("/v1/bat/modes", request, fields)

    modes = bat_modes

    def sweet_spot(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/sweet-spot``: the sweet spot(s) of a bat in a scene."""
        return self._post("/v1/sweet-spot", request, fields)

    def collision(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/collision``: one impact at ``impact_from_knob_m`` (or ``_in``)."""
        return self._post("/v1/collision", request, fields)

    def compare(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/compare``: ``baseline`` and ``variants`` side by side, with deltas."""
        return self._post("/v1/compare", request, fields)

    def optimize(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/optimize``: the best bat under constraints."""
        return self._post("/v1/optimize", request, fields)

    def frontier(self, request: Optional[JsonDict] = None, **fields: Any) -> RowStream:
        """``POST /v1/optimize`` with ``frontier`` (the best design at every value of one
        constraint) as NDJSON: a :class:`RowStream` of one row per value as the server solves it
        (its ``summary``, with the Pareto front, once read). ``frontier`` is e.g.
        ``{"constraint": "mass_oz", "from": 29, "to": 32, "count": 7}``."""
        body = _merge(request, fields)
        if "frontier" not in body:
            raise ValueError("frontier() needs a frontier: {\"constraint\": ..., \"values\": [...]}")
        body["format"] = "ndjson"
        return self.stream("POST", "/v1/optimize", body, kind="ndjson")

    def flight(self, request: Optional[JsonDict] = None, **fields: Any) -> JsonDict:
        """``POST /v1/flight``: batted-ball flight from ``launch`` (or ``launches``) (needs a
        server with /v1/flight)."""
        return self._post("/v1/flight", request, fields)

    def flights(self, launches: Any, chunk: int = 1024, request: Optional[JsonDict] = None,
                **fields: Any) -> Iterator[JsonDict]:
        """The flights of any number of launches, in order, sent ``chunk`` launches per
        ``POST /v1/flight`` (at most the server's ``--max-launches``, 4096 by default) with the
        rest of the request (``environment``, ``aero``, ``report_units``...) the same for all."""
        batch: List[JsonDict] = []
        for launch in launches:
            batch.append(launch)
            if len(batch) == chunk:
                yield from self._flight_batch(batch, request, fields)
                batch = []
        if batch:
            yield from self._flight_batch(batch, request, fields)

    def _flight_batch(self, batch: List[JsonDict], request: Optional[JsonDict],
                      fields: JsonDict) -> List[JsonDict]:
        body = _merge(request, fields)
        body.pop("launch", None)
        body["launches"] = batch
        return self.request("POST", "/v1/flight", body)["flights"]

    def explore(self, request: Optional[JsonDict] = None, **fields: Any) -> Any:
        """``POST /v1/explore``. With ``format`` ``json`` (the default) the whole answer
        (``rows`` and ``summary``); with ``ndjson`` or ``csv`` a :class:`RowStream` of the rows,
        read as the server streams them."""
        body = _merge(request, fields)
        if body.get("format", "json") in ("ndjson", "csv"):
            return self.stream("POST", "/v1/explore", body, kind=body["format"])
        return self.request("POST", "/v1/explore", body)

    def explore_rows(self, request: Optional[JsonDict] = None, **fields: Any) -> RowStream:
        """``POST /v1/explore`` as NDJSON: a :class:`RowStream` of the rows (its ``summary`` once
        read), in constant memory whatever the sweep's size."""
        fields["format"] = "ndjson"
        return self.explore(request, **fields)

    def explore_csv(self, request: Optional[JsonDict] = None, convert: bool = True,
                    **fields: Any) -> RowStream:
        """``POST /v1/explore`` as CSV: a :class:`RowStream` of dicts keyed by the columns."""
        body = _merge(request, fields)
        body["format"] = "csv"
        return self.stream("POST", "/v1/explore", body, convert=convert, kind="csv")

    # ---- jobs ----------------------------------------------------------------------------

    def submit(self, path: str, request: Optional[JsonDict] = None, **fields: Any) -> Job:
        """``POST /v1/jobs``: runs ``path`` (``/v1/explore`` or ``explore``) with the request as
        a job; returns the :class:`Job` (queued). A full queue is a 429, retried."""
        if not path.startswith("/"):
            path = "/v1/" + path
        info = self.request("POST", "/v1/jobs", {"path": path, "body": _merge(request, fields)})
        return Job(self, info)

    def run_job(self, path: str, request: Optional[JsonDict] = None,
                progress: Optional[Callable[[Job], Any]] = None, poll_s: float = 0.2,
                **fields: Any) -> Any:
        """Submits, waits (``progress(job)`` after each poll) and returns the result."""
        return self.submit(path, request, **fields).wait(progress, poll_s).result()

    def job(self, job_id: str) -> JsonDict:
        """``GET /v1/jobs/{id}``."""
        return self.request("GET", "/v1/jobs/" + urllib.parse.quote(job_id))

    def jobs(self, state: Optional[str] = None, limit: Optional[int] = None,
             offset: Optional[int] = None) -> JsonDict:
        """``GET /v1/jobs``: ``{"jobs": [...], "total", "next_offset"}``, newest first."""
        return self.request("GET", "/v1/jobs",
                            query={"state": state, "limit": limit, "offset": offset})

    def job_result(self, job_id: str) -> Any:
        """``GET /v1/jobs/{id}/result``."""
        return self.request("GET", "/v1/jobs/%s/result" % urllib.parse.quote(job_id))

    def cancel_job(self, job_id: str) -> JsonDict:
        """``DELETE /v1/jobs/{id}``: cancels a queued or running job, deletes a finished one."""
        return self.request("DELETE", "/v1/jobs/" + urllib.parse.quote(job_id))

    delete_job = cancel_job


def statcast_launches(rows: Any) -> Iterator[JsonDict]:
    """``/v1/flight`` launches from rows of a Statcast CSV (``csv.DictReader`` rows of Baseball
    Savant's search export): ``launch_speed`` (mph), ``launch_angle`` (deg), the spray angle
    from the hit coordinates ``hc_x``, ``hc_y`` (Savant's field image: home plate at (125.42,
    198.27); 0 = centre field, + toward right field), ``stand`` (R/L) as the batter's hand.
    Rows without a launch speed or angle (not batted balls) are skipped."""
    import math
    for row in rows:
        speed, angle = row.get("launch_speed"), row.get("launch_angle")
        if speed in (None, "", "null") or angle in (None, "", "null"):
            continue
        launch: JsonDict = {"exit_speed_mph": float(speed), "launch_angle_deg": float(angle)}
        hc_x, hc_y = row.get("hc_x"), row.get("hc_y")
        if hc_x not in (None, "", "null") and hc_y not in (None, "", "null"):
            spray = math.degrees(math.atan2(float(hc_x) - 125.42, 198.27 - float(hc_y)))
            launch["spray_angle_deg"] = max(-90.0, min(90.0, spray))
        stand = (row.get("stand") or "").upper()
        if stand in ("R", "L"):
            launch["batter_hand"] = "right" if stand == "R" else "left"
        yield launch
