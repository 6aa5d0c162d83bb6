// Validates Kubernetes manifests: every document of every file against the
// Kubernetes API schemas of kubernetes-models (the model class of its
// apiVersion and kind; an unknown kind fails), then the project's rules for
// pods: non-root, a RuntimeDefault seccomp profile, and each container with a
// read-only root filesystem, no privilege escalation, all capabilities
// dropped, and CPU and memory requests and limits.
//
//   node validate.mjs FILE.yaml...
//
// Run from a folder where `npm ci` installed package-lock.json's packages (the
// build copies this file there: build/tests/kubernetes/). Prints one line per
// document and exits 1 if any fails.
import { readFileSync } from "node:fs";
import { parseAllDocuments } from "yaml";

const files = process.argv.slice(2);
// The model classes of an apiVersion ("v1", "batch/v1", ...), or null.
async function modelsOf(apiVersion) {
  try {
    return await import(`kubernetes-models/${apiVersion}`);
  } catch {
    return null;
  }
}

// The pod template of a workload, or null.
function podSpecOf(doc) {
  switch (doc.kind) {
    case "Pod": return doc.spec;
    case "Job": return doc.spec?.template?.spec;
    case "CronJob": return doc.spec?.jobTemplate?.spec?.template?.spec;
    case "Deployment": case "StatefulSet": case "DaemonSet": case "ReplicaSet":
      return doc.spec?.template?.spec;
    default: return null;
  }
}

function podRules(pod) {
  const problems = [];
  const psc = pod.securityContext ?? {};
  if (psc.runAsNonRoot !== true) problems.push("pod securityContext.runAsNonRoot must be true");
  if (!(Number.isInteger(psc.runAsUser) && psc.runAsUser > 0)) {
    problems.push("pod securityContext.runAsUser must be a numeric non-root uid");
  }
  if (psc.seccompProfile?.type !== "RuntimeDefault") {
    problems.push("pod securityContext.seccompProfile.type must be RuntimeDefault");
  }
  for (const c of [...(pod.initContainers ?? []), ...(pod.containers ?? [])]) {
    const sc = c.securityContext ?? {};
    const where = `container ${c.name}`;
    if (sc.readOnlyRootFilesystem !== true) problems.push(`${where}: readOnlyRootFilesystem must be true`);
    if (sc.allowPrivilegeEscalation !== false) problems.push(`${where}: allowPrivilegeEscalation must be false`);
    if (!(sc.capabilities?.drop ?? []).includes("ALL")) problems.push(`${where}: capabilities.drop must include ALL`);
    for (const kind of ["requests", "limits"]) {
      for (const resource of ["cpu", "memory"]) {
        if (c.resources?.[kind]?.[resource] === undefined) {
          problems.push(`${where}: resources.${kind}.${resource} is missing`);
        }
      }
    }
  }
  return problems;
}

let failed = 0;
let documents = 0;
for (const file of files) {
  const docs = parseAllDocuments(readFileSync(file, "utf8"));
  for (const parsed of docs) {
    if (parsed.errors.length > 0) {
      console.log(`FAIL ${file}: YAML: ${parsed.errors[0].message}`);
      failed++;
      continue;
    }
    const doc = parsed.toJS();
    if (doc === null) continue;
    documents++;
    const name = `${file}: ${doc.kind ?? "?"}/${doc.metadata?.name ?? "?"}`;
    const problems = [];
    const models = await modelsOf(doc.apiVersion ?? "");
    const Model = models?.[doc.kind];
    if (!Model) {
      problems.push(`unknown apiVersion/kind ${doc.apiVersion}/${doc.kind}`);
    } else {
      try {
        new Model(doc).validate();
      } catch (error) {
        problems.push(`schema: ${error.message}`);
      }
    }
    const pod = podSpecOf(doc);
    if (pod) problems.push(...podRules(pod));
    if (problems.length > 0) {
      failed++;
      console.log(`FAIL ${name}\n  ${problems.join("\n  ")}`);
    } else {
      console.log(`ok   ${name}`);
    }
  }
}
console.log(`${documents} documents, ${failed} failed`);
if (documents === 0) {
  console.log("no documents: give the manifests to validate");
  process.exit(1);
}
process.exit(failed > 0 ? 1 : 0);
