// Validates Kubernetes manifests: every document of every file against the
// Kubernetes API schemas of kubernetes-models (the model class of its
// apiVersion and kind; an unknown kind fails), then the project's rules for
// pods: non-root, a RuntimeDefault seccomp profile, and each container with a
// read-only root filesystem, no privilege escalation, all capabilities
// dropped, and CPU and memory requests and limits. A kustomization
// (kustomize.config.k8s.io Kustomization or Component, which no API server
// knows) is checked instead for what `kubectl apply -k` needs: its resources and
// components exist, every image is pinned by a sha256 digest, and every
// replacement's source and targets name an object of its resources.
//
//   node validate.mjs FILE.yaml...
//
// Run from a folder where `npm ci` installed package-lock.json's packages (the
// build copies this file there: build/tests/kubernetes/). Prints one line per
// document and exits 1 if any fails.
import { existsSync, readFileSync, statSync } from "node:fs";
import { dirname, join } from "node:path";
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

// The objects ({kind, name}) of a kustomization's resources (files or folders with
// their own kustomization.yaml), for its replacements.
function objectsOf(folder, doc) {
  const objects = [];
  for (const resource of doc.resources ?? []) {
    const path = join(folder, resource);
    if (!existsSync(path) || statSync(path).isDirectory()) continue;
    for (const parsed of parseAllDocuments(readFileSync(path, "utf8"))) {
      const object = parsed.toJS();
      if (object?.kind) objects.push({ kind: object.kind, name: object.metadata?.name });
    }
  }
  return objects;
}

function kustomizationRules(file, doc) {
  const problems = [];
  if (!["Kustomization", "Component"].includes(doc.kind)) {
    return [`unknown kustomize kind ${doc.kind}`];
  }
  const folder = dirname(file);
  for (const entry of [...(doc.resources ?? []), ...(doc.components ?? [])]) {
    const path = join(folder, entry);
    if (!existsSync(path)) {
      problems.push(`${entry} does not exist`);
    } else if (statSync(path).isDirectory() && !existsSync(join(path, "kustomization.yaml"))) {
      problems.push(`${entry}/kustomization.yaml does not exist`);
    }
  }
  for (const image of doc.images ?? []) {
    if (!image.name) problems.push("an images entry without a name");
    if (!/^sha256:[0-9a-f]{64}$/.test(image.digest ?? "")) {
      problems.push(`image ${image.name}: must be pinned by a digest (sha256:<64 hex>), not ${image.newTag ?? "a tag"}`);
    }
  }
  const objects = objectsOf(folder, doc);
  const known = (select) =>
    objects.some((o) => o.kind === select?.kind && (select?.name === undefined || o.name === select.name));
  for (const replacement of doc.replacements ?? []) {
    if (!known(replacement.source)) {
      problems.push(`replacement source ${replacement.source?.kind}/${replacement.source?.name} is not among the resources`);
    }
    for (const target of replacement.targets ?? []) {
      if (!known(target.select)) {
        problems.push(`replacement target ${target.select?.kind}/${target.select?.name} is not among the resources`);
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
    if ((doc.apiVersion ?? "").startsWith("kustomize.config.k8s.io/")) {
      problems.push(...kustomizationRules(file, doc));
      if (problems.length > 0) {
        failed++;
        console.log(`FAIL ${name}\n  ${problems.join("\n  ")}`);
      } else {
        console.log(`ok   ${name}`);
      }
      continue;
    }
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
