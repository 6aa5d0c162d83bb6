# Sourced by bench/http_bench.sh, cpu_vs_nginx.sh and cpu_per_request.sh (not run on its own):
# the servers they measure on loopback, and what they read of them.
#
#   thread_switches PID...
# prints the context switches of the processes' threads, summed: "voluntary involuntary".
thread_switches() {
  local p
  for p in "$@"; do cat /proc/"$p"/task/*/status; done |
    awk '/^voluntary_ctxt_switches/ {v += $2} /^nonvoluntary_ctxt_switches/ {n += $2}
         END {print v, n}'
}
#
#   start_sweetspot SERVER WORK JOBS_DB
# starts SERVER on an ephemeral loopback port with the defaults but two (no access log, and up
# to 256 connections from one client address, as wrk is one), its log in WORK/server.log, and
# sets pid and port (exits with the log when no port appears within 10 s). The caller stops it.
start_sweetspot() {
  local server="$1" work="$2" jobs_db="$3"
  "$server" --port 0 --access-log 0 --max-connections-per-client 256 --jobs-db "$jobs_db" \
    2>"$work/server.log" &
  pid=$!
  port=""
  for _ in $(seq 100); do
    port="$(sed -n 's/.* listening on [^:]*:\([0-9]*\) .*/\1/p' "$work/server.log" | head -n1)"
    [ -n "$port" ] && break
    sleep 0.1
  done
  [ -n "$port" ] || { echo "no port in the server's log" >&2; cat "$work/server.log" >&2; exit 1; }
}

# Debian's nginx serving sweetspot's answer to one request as a static file, keep-alive, no
# access log:
#   start_nginx_static WORK BODY URL
# posts BODY to URL (the running sweetspot), keeps the answer as WORK/html/sweet-spot.json,
# starts nginx on a free loopback port with its files under WORK, waits until it answers, and
# sets nginx_pid and static_url (the file's address). The caller stops nginx (kill $nginx_pid).
start_nginx_static() {
  local work="$1" body="$2" url="$3" nginx_port="" candidate
  mkdir -p "$work/html"
  curl -sS -X POST -H 'Content-Type: application/json' -d "$body" "$url" >"$work/html/sweet-spot.json"
  while [ -z "$nginx_port" ]; do  # a loopback port nobody listens on
    candidate=$(( 20000 + RANDOM % 20000 ))
    (echo >"/dev/tcp/127.0.0.1/$candidate") 2>/dev/null || nginx_port="$candidate"
  done
  cat >"$work/nginx.conf" <<CONF
worker_processes auto;
events { worker_connections 4096; }
http {
  access_log off;
  keepalive_requests 100000;
  client_body_temp_path $work/body;
  proxy_temp_path $work/proxy;
  fastcgi_temp_path $work/fastcgi;
  uwsgi_temp_path $work/uwsgi;
  scgi_temp_path $work/scgi;
  server {
    listen 127.0.0.1:$nginx_port;
    root $work/html;
    location / { default_type application/json; }
  }
}
CONF
  /usr/sbin/nginx -p "$work" -c "$work/nginx.conf" \
    -g "daemon off; pid $work/nginx.pid; error_log $work/nginx-error.log;" &
  nginx_pid=$!
  static_url="http://127.0.0.1:$nginx_port/sweet-spot.json"
  for _ in $(seq 1 100); do
    curl -fsS "$static_url" >/dev/null 2>&1 && break
    sleep 0.1
  done
}
