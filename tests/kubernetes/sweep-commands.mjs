// Runs the shell commands of the Kubernetes sweep's containers (deploy/kubernetes/sweep/ and
// sweep-merge/) on this machine, as their pods would: no cluster, but the real sweetspot CLI,
// the manifests' own command lines, the Job's `completions` as N (the kustomization copies it
// into SHARDS) and JOB_COMPLETION_INDEX per pod, with /shards and /request mapped to a temporary
// folder. Shard 2 is made to fail on its first run (a `sweetspot` wrapper first on PATH exits 1
// for it while a marker file exists); checks that the merge then fails naming the missing
// shard, that the re-applied Job recomputes shard 2 alone (the others' files are kept
// untouched), and that the merge's rows are byte for byte the unsharded sweep's.
//
//   node sweep-commands.mjs REPOSITORY_ROOT SWEETSPOT_CLI
//
// Run from a folder where package-lock.json's packages are installed (build/tests/kubernetes/).
import { spawnSync } from "node:child_process";
import { chmodSync, mkdirSync, mkdtempSync, readFileSync, rmSync, statSync, writeFileSync, existsSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { parseAllDocuments } from "yaml";

const [root, cli] = process.argv.slice(2);
const documents = (file) =>
  parseAllDocuments(readFileSync(join(root, file), "utf8")).map((d) => d.toJS());
const sweepDocs = documents("deploy/kubernetes/sweep/explore-sweep.yaml");
const mergeDocs = documents("deploy/kubernetes/sweep-merge/explore-merge.yaml");
const shardJob = sweepDocs.find((d) => d.kind === "Job");
const request = sweepDocs.find((d) => d.kind === "ConfigMap").data["sweep.json"];
const mergeJob = mergeDocs.find((d) => d.kind === "Job");
const containerOf = (job) => job.spec.template.spec.containers[0];

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
}

const work = mkdtempSync(join(tmpdir(), "sweetspot-k8s-sweep-"));
const shardsDir = join(work, "shards");
const requestDir = join(work, "request");
const bin = join(work, "bin");
for (const dir of [shardsDir, requestDir, bin]) mkdirSync(dir);
writeFileSync(join(requestDir, "sweep.json"), request);
const marker = join(work, "fail-shard-2");
// `sweetspot` on the pods' PATH: the real CLI, but shard 2 fails while the marker exists.
writeFileSync(join(bin, "sweetspot"), `#!/bin/sh
case " $* " in *" --shard 2/"*) [ -e "${marker}" ] && { echo "shard 2 made to fail" >&2; exit 1; } ;; esac
exec "${cli}" "$@"
`);
chmodSync(join(bin, "sweetspot"), 0o755);

// A container's command line with the pod's mounts mapped into the temporary folder.
function run(container, env) {
  const script = container.args.join(" ").replaceAll("/shards", shardsDir).replaceAll("/request", requestDir);
  const result = spawnSync(container.command[0], [...container.command.slice(1), script], {
    env: { PATH: `${bin}:${process.env.PATH}`, ...env },
    encoding: "utf8",
  });
  return { status: result.status, out: result.stdout + result.stderr };
}

const shards = shardJob.spec.completions;
const applyShardJob = () =>
  Array.from({ length: shards }, (_, i) =>
    run(containerOf(shardJob), { JOB_COMPLETION_INDEX: String(i), SHARDS: String(shards) }));

try {
  writeFileSync(marker, "");
  const first = applyShardJob();
  check(first.every((r, i) => (i === 2 ? r.status === 1 : r.status === 0)),
        `first run: shard 2 of ${shards} fails, the others succeed (${first.map((r) => r.status)})`);
  const merge1 = run(containerOf(mergeJob), {});
  check(merge1.status !== 0 && merge1.out.includes(`missing shards of ${shards}: shard-2.ndjson`),
        `the merge refuses and names the missing shard: ${merge1.out.trim()}`);
  check(!existsSync(join(shardsDir, "sweep.ndjson")), "no sweep.ndjson after the failed merge");

  rmSync(marker);
  const kept = statSync(join(shardsDir, "shard-0.ndjson")).mtimeMs;
  const second = applyShardJob();
  check(second.every((r) => r.status === 0), "the Job applied again succeeds");
  check(second.filter((r) => r.out.includes("done before, kept")).length === shards - 1 &&
        !second[2].out.includes("done before"),
        "only shard 2 is computed again; the others are kept");
  check(statSync(join(shardsDir, "shard-0.ndjson")).mtimeMs === kept, "shard-0.ndjson untouched");
  const merge2 = run(containerOf(mergeJob), {});
  check(merge2.status === 0, `the merge succeeds: ${merge2.out.trim()}`);

  const whole = spawnSync(cli, ["explore", "--shard", "0/1", join(requestDir, "sweep.json")],
                          { encoding: "utf8", maxBuffer: 1 << 30 }).stdout.split("\n");
  const merged = readFileSync(join(shardsDir, "sweep.ndjson"), "utf8").split("\n");
  const rows = (lines) => lines.filter((l) => l && !l.startsWith('{"summary"')).join("\n");
  check(rows(whole).length > 0 && rows(merged) === rows(whole),
        `the merged rows (${merged.length - 2}) are byte for byte the unsharded sweep's`);
} finally {
  rmSync(work, { recursive: true, force: true });
}
console.log(failures === 0 ? "sweep commands: ok" : `sweep commands: ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
