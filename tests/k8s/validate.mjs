// Offline validation of limn's Kubernetes manifests (docker/k8s/), with no cluster:
//   1. YAML: every document parses, no duplicate keys.
//   2. Kubernetes' schemas, two ways, from the kubernetes-models package (generated from the
//      Kubernetes OpenAPI document): its validators (required fields, types, formats such as
//      quantities), and TypeScript's checker over its types, which also refuses unknown fields
//      and enum values that the schema validators let through ("replica:", "Indexd").
//   3. What no schema knows, the contract between the manifests and limn: probes on /healthz
//      and /readyz, the container port the image listens on, a configuration that limn accepts,
//      CPU equal to the workers and memory for them, a grace period longer than the drain,
//      selectors that select, the Indexed Job's --shard-count equal to its completions, the
//      merge step on the shards' volume, every kustomization complete; the job store: the
//      servers' LIMN_JOB_STORE a PostgreSQL URI from a Secret of their kustomization, naming the
//      database's Service, port, role, password and database, each pod its own LIMN_REPLICA,
//      and the database's StatefulSet with its data on a claim, ready only when it answers.
//
//   node tests/k8s/validate.mjs --modules NODE_MODULES [--self-test] MANIFEST_DIR
// Exits 1 and lists every problem when one is found. --self-test instead breaks the manifests
// in memory one way at a time and fails unless each breakage is caught.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";
import { pathToFileURL } from "node:url";

const args = process.argv.slice(2);
const option = (name) => {
  const i = args.indexOf(name);
  if (i < 0) return undefined;
  const [, value] = args.splice(i, 2);
  return value;
};
const modulesDir = path.resolve(option("--modules") ?? "node_modules");
const selfTest = args.includes("--self-test");
const manifestDir = path.resolve(args.filter((a) => a !== "--self-test")[0] ?? "docker/k8s");
const repoRoot = path.resolve(path.dirname(new URL(import.meta.url).pathname), "../..");

const require = createRequire(path.join(modulesDir, "noop.js"));
const YAML = require("yaml");
const ts = require("typescript");

// ---- loading ---------------------------------------------------------------------------------

// The tree: every kustomization and every object, each with the file it came from.
function load(dir) {
  const tree = { kustomizations: [], objects: [], errors: [] };
  const walk = (d) => {
    for (const entry of fs.readdirSync(d, { withFileTypes: true }).sort((a, b) => (a.name < b.name ? -1 : 1))) {
      const full = path.join(d, entry.name);
      if (entry.isDirectory()) walk(full);
      else if (/\.ya?ml$/.test(entry.name)) parseFile(tree, path.relative(dir, full), fs.readFileSync(full, "utf8"));
    }
  };
  walk(dir);
  return tree;
}

function parseFile(tree, file, text) {
  const docs = YAML.parseAllDocuments(text, { uniqueKeys: true, prettyErrors: true });
  docs.forEach((doc, index) => {
    for (const e of [...doc.errors, ...doc.warnings]) tree.errors.push(`${file}: YAML: ${e.message}`);
    if (doc.errors.length) return;
    const obj = doc.toJS();
    if (obj === null || obj === undefined) return;
    if (path.basename(file) === "kustomization.yaml") tree.kustomizations.push({ file, obj });
    else tree.objects.push({ file, index, obj });
  });
}

const where = (o) => `${o.file} (${o.obj?.kind ?? "?"} ${o.obj?.metadata?.name ?? "?"})`;

// ---- Kubernetes' schemas -----------------------------------------------------------------

function modelPath(obj) {
  if (typeof obj.apiVersion !== "string" || typeof obj.kind !== "string") return null;
  const file = path.join(modulesDir, "kubernetes-models", obj.apiVersion, `${obj.kind}.js`);
  return fs.existsSync(file) ? file : null;
}

async function schemaErrors(objects) {
  const errors = [];
  for (const o of objects) {
    const file = modelPath(o.obj);
    if (!file) {
      errors.push(`${where(o)}: no Kubernetes kind ${o.obj.kind} in ${o.obj.apiVersion}`);
      continue;
    }
    const Model = (await import(pathToFileURL(file)))[o.obj.kind];
    try {
      new Model(o.obj).validate();
    } catch (e) {
      errors.push(`${where(o)}: schema: ${e.message}`);
    }
  }
  return errors;
}

// A value as a TypeScript object literal, one property a line (so that an error's line names
// the property), keys unquoted where they can be (so that messages read 'replica', not '"replica"').
function tsLiteral(value, indent = "") {
  const inner = indent + "  ";
  if (Array.isArray(value)) {
    if (!value.length) return "[]";
    return `[\n${value.map((v) => inner + tsLiteral(v, inner)).join(",\n")}\n${indent}]`;
  }
  if (value && typeof value === "object") {
    const entries = Object.entries(value);
    if (!entries.length) return "{}";
    const key = (k) => (/^[A-Za-z_$][\w$]*$/.test(k) ? k : JSON.stringify(k));
    return `{\n${entries.map(([k, v]) => `${inner}${key(k)}: ${tsLiteral(v, inner)}`).join(",\n")}\n${indent}}`;
  }
  return JSON.stringify(value);
}

// One TypeScript program for many variants of the tree (the self-test's breakages), so that the
// checker starts once. Returns, per variant label, the errors found.
function typeErrors(variants) {
  const out = new Map(variants.map((v) => [v.label, []]));
  const lines = [];
  const owners = []; // per generated line: [label, object]
  let n = 0;
  for (const v of variants) {
    for (const o of v.objects) {
      const file = modelPath(o.obj);
      if (!file) continue; // reported by schemaErrors
      const spec = `kubernetes-models/${o.obj.apiVersion}/${o.obj.kind}`;
      const body = tsLiteral(o.obj).split("\n");
      const text = [`import type { I${o.obj.kind} as T${n} } from ${JSON.stringify(spec)};`,
        `export const v${n}: T${n} = ${body[0]}`, ...body.slice(1)];
      text[text.length - 1] += ";";
      for (const line of text) {
        lines.push(line);
        owners.push([v.label, o]);
      }
      n++;
    }
  }
  const dir = path.join(path.dirname(modulesDir), "generated");
  fs.mkdirSync(dir, { recursive: true });
  const source = path.join(dir, "manifests.ts");
  fs.writeFileSync(source, lines.join("\n") + "\n");
  const program = ts.createProgram([source], {
    strict: true, noEmit: true, skipLibCheck: true, types: [],
    module: ts.ModuleKind.NodeNext, moduleResolution: ts.ModuleResolutionKind.NodeNext,
    target: ts.ScriptTarget.ES2022,
  });
  for (const d of ts.getPreEmitDiagnostics(program)) {
    const message = ts.flattenDiagnosticMessageText(d.messageText, " ");
    if (!d.file || path.resolve(d.file.fileName) !== source) {
      for (const v of variants) out.get(v.label).push(`type check: ${message}`);
      continue;
    }
    const { line } = d.file.getLineAndCharacterOfPosition(d.start ?? 0);
    const [label, o] = owners[line];
    out.get(label).push(`${where(o)}: ${lines[line].trim().replace(/,$/, "")}: ${message}`);
  }
  return out;
}

// ---- quantities ----------------------------------------------------------------------------

function cores(q) {
  if (typeof q === "number") return q;
  const m = /^(\d+(?:\.\d+)?)(m?)$/.exec(String(q ?? ""));
  return m ? Number(m[1]) / (m[2] ? 1000 : 1) : NaN;
}

function bytes(q) {
  if (typeof q === "number") return q;
  const units = { "": 1, k: 1e3, M: 1e6, G: 1e9, T: 1e12, Ki: 2 ** 10, Mi: 2 ** 20, Gi: 2 ** 30, Ti: 2 ** 40 };
  const m = /^(\d+(?:\.\d+)?)(k|M|G|T|Ki|Mi|Gi|Ti)?$/.exec(String(q ?? ""));
  return m ? Number(m[1]) * units[m[2] ?? ""] : NaN;
}

const MiB = 2 ** 20;

// ---- limn's contract ---------------------------------------------------------------------

// What limn's memory needs were measured to be (bench/load_results.md, docs/operations.md):
// about 192 MiB idle, the reference cache up to its bound, and about 870 MiB per worker busy on
// a heavy reference (2 workers: 2446 MiB peak with the 512 MiB cache).
const idleBytes = 192 * MiB;
const perWorkerBytes = 870 * MiB;
// After SIGTERM: the drain (shutdownDrainMs), 2 s to write answers, 3 s for a stuck worker.
const afterDrainSeconds = 5;
const imagePort = 8080; // the image's LIMN_LISTEN
const imageConfig = "/etc/limn/limn.json"; // the image's LIMN_CONFIG

function subset(a, b) {
  return a && b && Object.entries(a).every(([k, v]) => b[k] === v);
}

function unknownKeys(value, reference, prefix = "") {
  const found = [];
  for (const [key, v] of Object.entries(value)) {
    const name = prefix + key;
    if (!(key in reference)) found.push(name);
    else if (v && typeof v === "object" && !Array.isArray(v) && reference[key] && typeof reference[key] === "object")
      found.push(...unknownKeys(v, reference[key], name + "."));
  }
  return found;
}

const imageName = (c) => String(c.image ?? "").split(":")[0];

function podSpecOf(obj) {
  return obj?.spec?.template?.spec;
}

function envOf(container, name) {
  return (container.env ?? []).find((e) => e.name === name);
}

// The file a container's volume mounts make visible at `file`: {volume, key} or null.
function mountedFile(pod, container, file) {
  for (const m of container.volumeMounts ?? []) {
    const dir = m.mountPath.replace(/\/$/, "");
    if (path.posix.dirname(file) !== dir) continue;
    const volume = (pod.volumes ?? []).find((v) => v.name === m.name);
    if (volume) return { volume, key: path.posix.basename(file), mount: m };
  }
  return null;
}

function configMapFile(all, pod, container, file, errors, what) {
  const found = mountedFile(pod, container, file);
  if (!found?.volume.configMap) {
    errors.push(`${what}: no ConfigMap volume is mounted where ${file} is read`);
    return null;
  }
  const cm = all.find((o) => o.obj.kind === "ConfigMap" && o.obj.metadata?.name === found.volume.configMap.name);
  const text = cm?.obj.data?.[found.key];
  if (text === undefined) {
    errors.push(`${what}: ConfigMap ${found.volume.configMap.name} has no key ${found.key} (${file})`);
    return null;
  }
  try {
    return { json: JSON.parse(text), configMap: cm };
  } catch (e) {
    errors.push(`${what}: ${file} in ConfigMap ${cm.obj.metadata.name} is not JSON: ${e.message}`);
    return null;
  }
}

function flagValue(list, flag) {
  const i = list.indexOf(flag);
  return i >= 0 ? list[i + 1] : undefined;
}

function checkPod(all, o, errors) {
  const pod = podSpecOf(o.obj);
  const what = where(o);
  if (!pod) return;
  if (pod.securityContext?.runAsNonRoot !== true) errors.push(`${what}: securityContext.runAsNonRoot must be true`);
  const volumes = new Map((pod.volumes ?? []).map((v) => [v.name, v]));
  for (const t of o.obj.spec?.volumeClaimTemplates ?? []) volumes.set(t.metadata?.name, { persistentVolumeClaim: {} });
  for (const v of pod.volumes ?? []) {
    if (v.configMap && !all.some((x) => x.obj.kind === "ConfigMap" && x.obj.metadata?.name === v.configMap.name))
      errors.push(`${what}: volume ${v.name} names ConfigMap ${v.configMap.name}, which no manifest defines`);
    if (v.persistentVolumeClaim &&
        !all.some((x) => x.obj.kind === "PersistentVolumeClaim" && x.obj.metadata?.name === v.persistentVolumeClaim.claimName))
      errors.push(`${what}: volume ${v.name} names PersistentVolumeClaim ${v.persistentVolumeClaim.claimName}, which no manifest defines`);
  }
  for (const c of pod.containers ?? []) {
    const cw = `${what} container ${c.name}`;
    const sc = c.securityContext ?? {};
    if (sc.readOnlyRootFilesystem !== true) errors.push(`${cw}: securityContext.readOnlyRootFilesystem must be true`);
    if (sc.allowPrivilegeEscalation !== false) errors.push(`${cw}: securityContext.allowPrivilegeEscalation must be false`);
    if (!(sc.capabilities?.drop ?? []).includes("ALL")) errors.push(`${cw}: securityContext.capabilities.drop must include ALL`);
    for (const m of c.volumeMounts ?? [])
      if (!volumes.has(m.name)) errors.push(`${cw}: volumeMount ${m.name} names no volume of the pod`);
    // Mesa's shader cache, matplotlib and PostgreSQL's tools write under /tmp; the root is read-only.
    if (!(c.volumeMounts ?? []).some((m) => m.mountPath === "/tmp"))
      errors.push(`${cw}: nothing is mounted at /tmp (the root filesystem is read-only)`);
    const req = c.resources?.requests ?? {}, lim = c.resources?.limits ?? {};
    for (const r of ["cpu", "memory"])
      if (req[r] === undefined || lim[r] === undefined) errors.push(`${cw}: resources need requests and limits of ${r}`);
    if (bytes(lim.memory) < bytes(req.memory)) errors.push(`${cw}: memory limit below its request`);
    // The one StatefulSet is the job store's database; every other pod runs limn.
    if (o.obj.kind === "StatefulSet") {
      if (imageName(c) !== "postgres") errors.push(`${cw}: image ${c.image} is not PostgreSQL's (postgres)`);
      continue;
    }
    if (!["limn", "limn-report"].includes(imageName(c))) errors.push(`${cw}: image ${c.image} is not limn's (limn or limn-report)`);
    if (!["serve", "batch", "render"].includes((c.args ?? [])[0]))
      errors.push(`${cw}: args must start with a limn command (serve, batch, render), not ${JSON.stringify(c.args)}`);
    const lp = envOf(c, "LP_NUM_THREADS");
    if (lp && Number(lp.value) > cores(lim.cpu)) errors.push(`${cw}: LP_NUM_THREADS ${lp.value} exceeds the CPU limit`);
  }
}

// The configuration a limn container reads (LIMN_CONFIG, else the image's file): only limn's
// keys, "workers" set and equal to the CPU, memory for them. Returns it with defaults filled in.
function checkWorkers(all, pod, c, cw, errors) {
  const configPath = envOf(c, "LIMN_CONFIG")?.value ?? imageConfig;
  const found = configMapFile(all, pod, c, configPath, errors, cw);
  if (!found) return null;
  const config = found.json;
  const defaults = JSON.parse(fs.readFileSync(path.join(repoRoot, "configs/default.json"), "utf8"));
  for (const key of unknownKeys(config, defaults))
    errors.push(`${cw}: configuration key "${key}" is not one of limn's (configs/default.json)`);
  const workers = config.workers;
  if (!Number.isInteger(workers) || workers < 1) {
    errors.push(`${cw}: the configuration must set "workers" (0 means the node's cores, not the pod's): ${workers}`);
    return null;
  }
  const req = c.resources?.requests ?? {}, lim = c.resources?.limits ?? {};
  if (cores(req.cpu) !== workers || cores(lim.cpu) !== workers)
    errors.push(`${cw}: CPU requests and limits (${req.cpu}, ${lim.cpu}) must equal the ${workers} workers`);
  const cache = config.referenceCacheBytes ?? defaults.referenceCacheBytes;
  const need = idleBytes + cache + workers * perWorkerBytes;
  if (!(bytes(lim.memory) >= need))
    errors.push(`${cw}: memory limit ${lim.memory} is below what ${workers} workers and a ${Math.round(cache / MiB)} MiB reference cache need (${Math.round(need / MiB)} MiB)`);
  return { ...defaults, ...config };
}

function checkServer(all, o, errors) {
  const pod = podSpecOf(o.obj);
  for (const c of pod?.containers ?? []) {
    if ((c.args ?? [])[0] !== "serve") continue;
    const cw = `${where(o)} container ${c.name}`;
    const listen = envOf(c, "LIMN_LISTEN")?.value;
    const port = listen ? Number(listen.split(":").pop()) : imagePort;
    const http = (c.ports ?? []).find((p) => p.containerPort === port);
    if (!http) errors.push(`${cw}: no containerPort ${port}, where limn listens (LIMN_LISTEN)`);
    const probe = (name, wanted) => {
      const p = c[name];
      if (!p) return name !== "startupProbe" && errors.push(`${cw}: no ${name}`);
      if (p.httpGet?.path !== wanted) errors.push(`${cw}: ${name} must GET ${wanted}, not ${p.httpGet?.path}`);
      const pp = p.httpGet?.port;
      if (pp !== port && !(http && pp === http.name)) errors.push(`${cw}: ${name} port ${pp} is not limn's port ${port}`);
    };
    probe("livenessProbe", "/healthz");
    probe("readinessProbe", "/readyz");
    probe("startupProbe", "/healthz");

    const config = checkWorkers(all, pod, c, cw, errors);
    if (!config) continue;
    const drain = config.shutdownDrainMs / 1000;
    const preStop = c.lifecycle?.preStop?.exec?.command;
    const sleep = preStop?.[0] === "sleep" ? Number(preStop[1]) : (c.lifecycle?.preStop?.sleep?.seconds ?? 0);
    const grace = pod.terminationGracePeriodSeconds ?? 30;
    if (grace < sleep + drain + afterDrainSeconds)
      errors.push(`${where(o)}: terminationGracePeriodSeconds ${grace} is shorter than preStop ${sleep} s + drain ${drain} s + ${afterDrainSeconds} s`);
  }
}

function selects(all, selector, kinds = ["Deployment"]) {
  return all.filter((x) => kinds.includes(x.obj.kind) && subset(selector, x.obj.spec?.template?.metadata?.labels));
}

function checkBatch(all, errors) {
  const jobs = all.filter((o) => o.obj.kind === "Job");
  const shards = jobs.filter((o) => podSpecOf(o.obj)?.containers?.some((c) => c.args?.[0] === "batch" && c.args?.[1] !== "--report"));
  const reports = jobs.filter((o) => podSpecOf(o.obj)?.containers?.some((c) => c.args?.[0] === "batch" && c.args?.[1] === "--report"));
  if (shards.length !== 1) errors.push(`batch: want one Job running limn batch over shards, found ${shards.length}`);
  if (reports.length !== 1) errors.push(`batch: want one Job running limn batch --report, found ${reports.length}`);
  let resultsClaim;
  for (const o of shards) {
    const spec = o.obj.spec ?? {};
    const pod = podSpecOf(o.obj);
    const what = where(o);
    if (spec.completionMode !== "Indexed") errors.push(`${what}: completionMode must be Indexed (each pod's JOB_COMPLETION_INDEX is its shard)`);
    if (!Number.isInteger(spec.completions) || spec.completions < 1) errors.push(`${what}: completions must be set`);
    if ((spec.parallelism ?? 1) > spec.completions) errors.push(`${what}: parallelism above completions`);
    if (pod.restartPolicy !== "Never") errors.push(`${what}: restartPolicy must be Never`);
    for (const c of pod.containers.filter((c) => c.args?.[0] === "batch")) {
      const a = c.args;
      // A shard renders with `workers` threads too: the node's cores unless configured.
      checkWorkers(all, pod, c, `${what} container ${c.name}`, errors);
      const count = flagValue(a, "--shard-count");
      if (Number(count) !== spec.completions)
        errors.push(`${what}: --shard-count ${count} must equal completions ${spec.completions}`);
      if (a.includes("--shard-index") || envOf(c, "JOB_COMPLETION_INDEX"))
        errors.push(`${what}: the shard index must come from the Job controller's JOB_COMPLETION_INDEX`);
      const specFile = a[1];
      if (!specFile || specFile.startsWith("-")) errors.push(`${what}: limn batch needs its SPEC file first`);
      else configMapFile(all, pod, c, path.posix.join(specFile), errors, `${what} container ${c.name}`);
      const out = flagValue(a, "--out");
      const mount = (c.volumeMounts ?? []).find((m) => m.mountPath.replace(/\/$/, "") === out);
      const volume = (pod.volumes ?? []).find((v) => v.name === mount?.name);
      if (!volume?.persistentVolumeClaim) errors.push(`${what}: --out ${out} is not a mounted PersistentVolumeClaim`);
      else resultsClaim = volume.persistentVolumeClaim.claimName;
    }
  }
  for (const o of reports) {
    const pod = podSpecOf(o.obj);
    for (const c of pod.containers.filter((c) => c.args?.[1] === "--report")) {
      const dir = c.args[2];
      const mount = (c.volumeMounts ?? []).find((m) => m.mountPath.replace(/\/$/, "") === dir);
      const claim = (pod.volumes ?? []).find((v) => v.name === mount?.name)?.persistentVolumeClaim?.claimName;
      if (!claim || claim !== resultsClaim)
        errors.push(`${where(o)}: --report ${dir} is not the shards' volume (${resultsClaim}), but ${claim}`);
      if (!String(c.image).startsWith("limn-report:"))
        errors.push(`${where(o)}: the merge step needs the report image (python3, matplotlib), not ${c.image}`);
    }
  }
}

function checkService(all, errors) {
  for (const o of all) {
    const { kind, spec = {} } = o.obj;
    if (kind === "Service") {
      const targets = selects(all, spec.selector, ["Deployment", "StatefulSet"]);
      if (!targets.length) errors.push(`${where(o)}: selector ${JSON.stringify(spec.selector)} selects no Deployment's or StatefulSet's pods`);
      for (const p of spec.ports ?? []) {
        const ok = targets.some((d) => (podSpecOf(d.obj)?.containers ?? []).some((c) =>
          (c.ports ?? []).some((cp) => cp.name === p.targetPort || cp.containerPort === p.targetPort)));
        if (targets.length && !ok) errors.push(`${where(o)}: targetPort ${p.targetPort} is no container port of the pods`);
      }
    }
    if (["Deployment", "StatefulSet"].includes(kind) && !subset(spec.selector?.matchLabels, spec.template?.metadata?.labels))
      errors.push(`${where(o)}: selector.matchLabels do not match the pod template's labels`);
    if (kind === "HorizontalPodAutoscaler") {
      const t = spec.scaleTargetRef ?? {};
      if (!all.some((x) => x.obj.kind === t.kind && x.obj.metadata?.name === t.name))
        errors.push(`${where(o)}: scaleTargetRef ${t.kind}/${t.name} is not defined`);
      if ((spec.minReplicas ?? 1) > spec.maxReplicas) errors.push(`${where(o)}: minReplicas above maxReplicas`);
    }
    if (kind === "PodDisruptionBudget") {
      const targets = selects(all, spec.selector?.matchLabels);
      if (!targets.length) errors.push(`${where(o)}: selector selects no Deployment's pods`);
      for (const d of targets) {
        const hpa = all.find((x) => x.obj.kind === "HorizontalPodAutoscaler" && x.obj.spec?.scaleTargetRef?.name === d.obj.metadata.name);
        const fewest = hpa?.obj.spec?.minReplicas ?? d.obj.spec?.replicas ?? 1;
        if (typeof spec.minAvailable === "number" && spec.minAvailable >= fewest)
          errors.push(`${where(o)}: minAvailable ${spec.minAvailable} leaves no pod of ${fewest} evictable: node drains would block`);
      }
    }
  }
}

// ---- the job store ---------------------------------------------------------------------------

// POST /v1/jobs keeps its jobs in one store that every replica of limn serve shares: a
// PostgreSQL database (limn creates its tables itself), here a StatefulSet unless the URI names
// a managed one. Each replica names itself in the rows and leases it takes (LIMN_REPLICA).
const postgresPort = 5432; // the postgres image's
const postgresData = "/var/lib/postgresql/data"; // the postgres image's PGDATA

const within = (file, dir) => {
  const d = path.posix.normalize(dir).replace(/\/$/, "");
  const f = path.posix.normalize(file).replace(/\/$/, "");
  return f === d || f.startsWith(d + "/");
};

// The kustomization whose resources list a manifest's file.
function kustomizationOf(tree, file) {
  return tree.kustomizations.find((k) => (k.obj.resources ?? []).some((r) =>
    path.posix.normalize(path.posix.join(path.posix.dirname(k.file), r)) === file));
}

// The value a secretKeyRef of `o`'s pods reads: the Secret must be a manifest that the same
// kustomization applies, with that key. Undefined, and what is wrong in errors, otherwise.
function secretRef(tree, o, ref, what, errors) {
  const secret = tree.objects.find((x) => x.obj.kind === "Secret" && x.obj.metadata?.name === ref.name);
  if (!secret) {
    errors.push(`${what} names Secret ${ref.name}, which no manifest defines`);
    return undefined;
  }
  const mine = kustomizationOf(tree, o.file);
  if (mine && kustomizationOf(tree, secret.file) !== mine)
    errors.push(`${what}: Secret ${ref.name} (${secret.file}) is not applied by ${mine.file}, which applies ${where(o)}`);
  const { stringData = {}, data = {} } = secret.obj;
  if (stringData[ref.key] !== undefined) return String(stringData[ref.key]);
  if (data[ref.key] !== undefined) return Buffer.from(String(data[ref.key]), "base64").toString("utf8");
  errors.push(`${what}: Secret ${ref.name} has no key ${ref.key}`);
  return undefined;
}

const postgresContainers = (o) => (podSpecOf(o.obj)?.containers ?? []).filter((c) => imageName(c) === "postgres");

// Where LIMN_JOB_STORE leads: a URI limn takes, at the database's Service and port, with its
// role, password and database.
function checkStoreUri(tree, cw, uri, errors) {
  const all = tree.objects;
  if (uri.startsWith("sqlite:")) {
    errors.push(`${cw}: LIMN_JOB_STORE is a SQLite file (${uri}): each pod would keep its own, and replicas would not share jobs`);
    return;
  }
  let url;
  try {
    url = new URL(uri);
  } catch {
    url = null;
  }
  if (!url || !["postgresql:", "postgres:"].includes(url.protocol)) {
    errors.push(`${cw}: LIMN_JOB_STORE is not a postgresql:// URI (limn takes sqlite:PATH or a libpq URI)`);
    return;
  }
  const databases = all.filter((x) => x.obj.kind === "StatefulSet" && postgresContainers(x).length);
  const host = decodeURIComponent(url.hostname);
  // A Service of these manifests: its bare name, or name.namespace.svc[.cluster.local].
  const service = (!host.includes(".") || /\.svc(\.|$)/.test(host)) &&
    all.find((x) => x.obj.kind === "Service" && x.obj.metadata?.name === host.split(".")[0]);
  if (!service) {
    // Elsewhere: a managed database, which no manifest here can vouch for; but then no
    // StatefulSet of PostgreSQL should be running beside it unused.
    if (databases.length)
      errors.push(`${cw}: LIMN_JOB_STORE points at ${host}, not at the Service of the job store's StatefulSet (${databases.map((d) => d.obj.spec?.serviceName).join(", ")})`);
    return;
  }
  const name = service.obj.metadata.name;
  const port = Number(url.port || postgresPort);
  if (!(service.obj.spec?.ports ?? []).some((p) => p.port === port))
    errors.push(`${cw}: LIMN_JOB_STORE's port ${port} is not a port of Service ${name}`);
  const db = databases.find((d) => subset(service.obj.spec?.selector, d.obj.spec?.template?.metadata?.labels));
  if (!db) {
    errors.push(`${cw}: LIMN_JOB_STORE's Service ${name} selects no PostgreSQL StatefulSet's pods`);
    return;
  }
  const pc = postgresContainers(db)[0];
  const role = decodeURIComponent(url.username);
  const wantRole = envOf(pc, "POSTGRES_USER")?.value ?? "postgres";
  if (role !== wantRole) errors.push(`${cw}: LIMN_JOB_STORE's role ${role || "(none)"} is not the database's POSTGRES_USER ${wantRole}`);
  // libpq's database is the role's name when the URI names none.
  const database = decodeURIComponent(url.pathname.replace(/^\//, "")) || role;
  const wantDatabase = envOf(pc, "POSTGRES_DB")?.value ?? wantRole;
  if (database !== wantDatabase) errors.push(`${cw}: LIMN_JOB_STORE's database ${database} is not the database's POSTGRES_DB ${wantDatabase}`);
  const pw = envOf(pc, "POSTGRES_PASSWORD");
  const password = pw?.valueFrom?.secretKeyRef ? secretRef(tree, db, pw.valueFrom.secretKeyRef, `${where(db)} container ${pc.name}: POSTGRES_PASSWORD`, []) : pw?.value;
  if (password !== undefined && decodeURIComponent(url.password) !== password)
    errors.push(`${cw}: LIMN_JOB_STORE's password is not the database's POSTGRES_PASSWORD`);
}

function checkJobStore(tree, errors) {
  const all = tree.objects;
  for (const o of all.filter((x) => x.obj.kind === "Deployment")) {
    for (const c of (podSpecOf(o.obj)?.containers ?? []).filter((c) => c.args?.[0] === "serve")) {
      const cw = `${where(o)} container ${c.name}`;
      const store = envOf(c, "LIMN_JOB_STORE");
      const ref = store?.valueFrom?.secretKeyRef;
      if (!store) {
        errors.push(`${cw}: no LIMN_JOB_STORE: each pod would keep a SQLite file of its own (on a read-only root), and replicas would not share jobs`);
      } else if (!ref) {
        errors.push(`${cw}: LIMN_JOB_STORE must come from a Secret (secretKeyRef): the URI holds the database's password`);
      } else {
        if (ref.optional) errors.push(`${cw}: LIMN_JOB_STORE's secretKeyRef must not be optional: without the Secret, each pod would keep a SQLite file of its own`);
        const uri = secretRef(tree, o, ref, `${cw}: LIMN_JOB_STORE`, errors);
        if (uri !== undefined) checkStoreUri(tree, cw, uri, errors);
      }
      const replica = envOf(c, "LIMN_REPLICA");
      if (replica?.valueFrom?.fieldRef?.fieldPath !== "metadata.name")
        errors.push(`${cw}: LIMN_REPLICA must be the pod's name (fieldRef metadata.name), not ${JSON.stringify(replica?.value ?? replica?.valueFrom ?? null)}: it names the replica in the rows and leases it takes, and pods sharing one would renew each other's leases`);
    }
  }
  for (const o of all.filter((x) => x.obj.kind === "StatefulSet")) {
    const what = where(o);
    const spec = o.obj.spec ?? {};
    const pod = podSpecOf(o.obj);
    if ((spec.replicas ?? 1) !== 1)
      errors.push(`${what}: replicas ${spec.replicas}: PostgreSQL here is one primary; more pods would be separate databases, each on a volume of its own`);
    const service = all.find((x) => x.obj.kind === "Service" && x.obj.metadata?.name === spec.serviceName);
    if (!service) errors.push(`${what}: serviceName ${spec.serviceName} names no Service of the manifests`);
    else {
      if (service.obj.spec?.clusterIP !== "None")
        errors.push(`${where(service)}: must be headless (clusterIP: None), as the serviceName of ${what}`);
      if (!subset(service.obj.spec?.selector, spec.template?.metadata?.labels))
        errors.push(`${where(service)}: selector does not select the pods of ${what}, whose serviceName it is`);
    }
    const sc = pod?.securityContext ?? {};
    if (sc.fsGroup === undefined)
      errors.push(`${what}: securityContext.fsGroup must be set: the claim is root's otherwise, and PostgreSQL runs as user ${sc.runAsUser}`);
    if (sc.fsGroupChangePolicy !== "OnRootMismatch")
      errors.push(`${what}: securityContext.fsGroupChangePolicy must be OnRootMismatch: a recursive change at every start makes PGDATA group-writable, and PostgreSQL then refuses to start`);
    const claims = new Set((spec.volumeClaimTemplates ?? []).map((t) => t.metadata?.name));
    for (const c of postgresContainers(o)) {
      const cw = `${what} container ${c.name}`;
      const data = envOf(c, "PGDATA")?.value ?? postgresData;
      const mount = (c.volumeMounts ?? []).filter((m) => within(data, m.mountPath))
        .sort((a, b) => b.mountPath.length - a.mountPath.length)[0];
      if (!mount || !claims.has(mount.name))
        errors.push(`${cw}: PGDATA ${data} is not on a volumeClaimTemplate (${mount ? `but on volume ${mount.name}` : "but in the container"}): the jobs would go with the pod`);
      else if (within(mount.mountPath, data))
        errors.push(`${cw}: PGDATA ${data} must be a directory below the volume's root ${mount.mountPath}: initdb wants an empty directory, and a new volume may hold lost+found`);
      if (!(c.readinessProbe?.exec?.command ?? []).join(" ").includes("pg_isready"))
        errors.push(`${cw}: no readinessProbe running pg_isready: the Service would send limn to a database still starting`);
      if (!(c.ports ?? []).some((p) => p.containerPort === postgresPort))
        errors.push(`${cw}: no containerPort ${postgresPort}, where PostgreSQL listens`);
      const pw = envOf(c, "POSTGRES_PASSWORD");
      if (!pw?.valueFrom?.secretKeyRef) errors.push(`${cw}: POSTGRES_PASSWORD must come from a Secret (secretKeyRef)`);
      else secretRef(tree, o, pw.valueFrom.secretKeyRef, `${cw}: POSTGRES_PASSWORD`, errors);
    }
  }
}

function checkKustomizations(tree, errors) {
  const allowed = new Set(["apiVersion", "kind", "resources", "images", "namespace", "labels", "commonAnnotations", "patches", "components"]);
  const listed = new Map();
  for (const k of tree.kustomizations) {
    const dir = path.posix.dirname(k.file);
    const { obj } = k;
    if (obj.apiVersion !== "kustomize.config.k8s.io/v1beta1" || obj.kind !== "Kustomization")
      errors.push(`${k.file}: not a kustomize.config.k8s.io/v1beta1 Kustomization`);
    for (const key of Object.keys(obj)) if (!allowed.has(key)) errors.push(`${k.file}: unknown or unused field ${key}`);
    const mine = [];
    for (const r of obj.resources ?? []) {
      const file = path.posix.normalize(path.posix.join(dir, r));
      const objects = tree.objects.filter((o) => o.file === file);
      if (!objects.length) errors.push(`${k.file}: resource ${r} is not a manifest here`);
      listed.set(file, (listed.get(file) ?? 0) + 1);
      mine.push(...objects);
    }
    for (const image of obj.images ?? []) {
      const used = mine.some((o) => (podSpecOf(o.obj)?.containers ?? []).some((c) => String(c.image).split(":")[0] === image.name));
      if (!used) errors.push(`${k.file}: images entry ${image.name} matches no container of its resources`);
    }
  }
  for (const file of new Set(tree.objects.map((o) => o.file))) {
    if (!listed.has(file)) errors.push(`${file}: listed in no kustomization.yaml`);
    else if (listed.get(file) > 1) errors.push(`${file}: listed in more than one kustomization.yaml`);
  }
}

function contractErrors(tree) {
  const errors = [];
  const all = tree.objects;
  const seen = new Set();
  for (const o of all) {
    const id = `${o.obj.kind}/${o.obj.metadata?.name}`;
    if (seen.has(id)) errors.push(`${where(o)}: ${id} is defined twice`);
    seen.add(id);
    if (o.obj.metadata?.labels?.["app.kubernetes.io/name"] !== "limn")
      errors.push(`${where(o)}: label app.kubernetes.io/name must be limn`);
    checkPod(all, o, errors);
    if (o.obj.kind === "Deployment") checkServer(all, o, errors);
  }
  checkService(all, errors);
  checkBatch(all, errors);
  checkJobStore(tree, errors);
  checkKustomizations(tree, errors);
  return errors;
}

async function validate(tree) {
  let contract;
  try {
    contract = contractErrors(tree);
  } catch (e) {
    // A manifest broken in a way no check foresaw still fails, and says where it tripped.
    contract = [`the checks of limn's contract could not run: ${e.stack}`];
  }
  return [...tree.errors, ...(await schemaErrors(tree.objects)), ...contract];
}

// ---- the self-test ---------------------------------------------------------------------------

// Each breakage, done on a copy of the real tree, and a piece of the error that must catch it.
const find = (tree, kind, name) => tree.objects.find((o) => o.obj.kind === kind && (!name || o.obj.metadata.name === name)).obj;
const top = (t) => t.kustomizations.find((k) => k.file === "kustomization.yaml");
const server = (t) => podSpecOf(find(t, "Deployment")).containers[0];
const shardJob = (t) => find(t, "Job", "limn-batch");
const storeSecret = (t) => find(t, "Secret", "limn-job-store");
const database = (t) => find(t, "StatefulSet", "limn-postgres");
const databaseContainer = (t) => podSpecOf(database(t)).containers[0];
const setStoreUri = (t, f) => {
  const data = storeSecret(t).stringData;
  const url = new URL(data.LIMN_JOB_STORE);
  f(url);
  data.LIMN_JOB_STORE = url.toString();
};
const setConfig = (t, f) => {
  const cm = find(t, "ConfigMap", "limn-config");
  const c = JSON.parse(cm.data["limn.json"]);
  f(c);
  cm.data["limn.json"] = JSON.stringify(c);
};
const breakages = [
  ["a misspelt field", "'replica' does not exist", (t) => { find(t, "Deployment").spec.replica = 3; }],
  ["a field of the wrong type", "replicas must be integer", (t) => { find(t, "Deployment").spec.replicas = "two"; }],
  ["a required field left out", "required property containers", (t) => { delete podSpecOf(find(t, "Deployment")).containers; }],
  ["an unknown enum value", '"Indexd"', (t) => { shardJob(t).spec.completionMode = "Indexd"; }],
  ["a malformed quantity", 'must match format "quantity"', (t) => { server(t).resources.limits.memory = "3 GB"; }],
  ["a kind that does not exist", "no Kubernetes kind Deploymnt", (t) => { find(t, "Deployment").kind = "Deploymnt"; }],
  ["readiness on the wrong path", "readinessProbe must GET /readyz", (t) => { server(t).readinessProbe.httpGet.path = "/ready"; }],
  ["liveness on the wrong port", "livenessProbe port 9090", (t) => { server(t).livenessProbe.httpGet.port = 9090; }],
  ["a container port limn does not listen on", "no containerPort 8080", (t) => { server(t).ports[0].containerPort = 8081; }],
  ["more workers than cores", "must equal the 4 workers", (t) => setConfig(t, (c) => { c.workers = 4; })],
  ["workers left to the node's cores", 'must set "workers"', (t) => setConfig(t, (c) => { c.workers = 0; })],
  ["a configuration key limn refuses", '"wrokers" is not one of', (t) => setConfig(t, (c) => { c.wrokers = 2; })],
  ["a configuration that is not JSON", "is not JSON", (t) => { find(t, "ConfigMap", "limn-config").data["limn.json"] = "{workers: 2"; }],
  ["too little memory for the workers", "memory limit 1Gi is below", (t) => { server(t).resources.limits.memory = "1Gi"; server(t).resources.requests.memory = "1Gi"; }],
  ["a grace period shorter than the drain", "terminationGracePeriodSeconds 10", (t) => { podSpecOf(find(t, "Deployment")).terminationGracePeriodSeconds = 10; }],
  ["a writable root filesystem", "readOnlyRootFilesystem must be true", (t) => { server(t).securityContext.readOnlyRootFilesystem = false; }],
  ["running as root allowed", "runAsNonRoot must be true", (t) => { delete podSpecOf(find(t, "Deployment")).securityContext.runAsNonRoot; }],
  ["a Service that selects nothing", "selects no Deployment", (t) => { find(t, "Service", "limn").spec.selector["app.kubernetes.io/component"] = "sever"; }],
  ["an HPA aimed at nothing", "scaleTargetRef Deployment/lim ", (t) => { find(t, "HorizontalPodAutoscaler").spec.scaleTargetRef.name = "lim"; }],
  ["a PDB that blocks drains", "leaves no pod of 2 evictable", (t) => { find(t, "PodDisruptionBudget").spec.minAvailable = 2; }],
  ["shards that do not cover the Job", "--shard-count 3 must equal completions 4", (t) => { const c = podSpecOf(shardJob(t)).containers[0]; c.args[c.args.indexOf("--shard-count") + 1] = "3"; }],
  ["a fixed shard index", "JOB_COMPLETION_INDEX", (t) => { podSpecOf(shardJob(t)).containers[0].args.push("--shard-index", "0"); }],
  ["a Job that is not Indexed", "completionMode must be Indexed", (t) => { delete shardJob(t).spec.completionMode; }],
  ["shards writing off the volume", "--out /tmp/results is not a mounted", (t) => { const a = podSpecOf(shardJob(t)).containers[0].args; a[a.indexOf("--out") + 1] = "/tmp/results"; }],
  ["a merge step on another volume", "is not the shards' volume", (t) => { podSpecOf(find(t, "Job", "limn-batch-report")).containers[0].volumeMounts[0].mountPath = "/other"; }],
  ["a shard with more workers than cores", "(2, 2) must equal the 3 workers", (t) => {
    const cm = find(t, "ConfigMap", "limn-batch-spec");
    cm.data["limn.json"] = JSON.stringify({ ...JSON.parse(cm.data["limn.json"]), workers: 3 });
  }],
  ["a volume naming a missing ConfigMap", "names ConfigMap limn-batch-spek", (t) => { podSpecOf(shardJob(t)).volumes.find((v) => v.configMap).configMap.name = "limn-batch-spek"; }],
  ["a manifest no kustomization lists", "listed in no kustomization.yaml", (t) => { top(t).obj.resources.pop(); }],
  ["a kustomization naming a missing file", "resource hpa.yml is not a manifest", (t) => { top(t).obj.resources.push("hpa.yml"); }],
  ["an image override that matches nothing", "images entry limm matches no container", (t) => { top(t).obj.images[0].name = "limm"; }],
  // The job store.
  ["no job store: a SQLite file per pod", "no LIMN_JOB_STORE", (t) => { server(t).env = server(t).env.filter((e) => e.name !== "LIMN_JOB_STORE"); }],
  ["a job store URI in the pod spec", "LIMN_JOB_STORE must come from a Secret", (t) => {
    const e = envOf(server(t), "LIMN_JOB_STORE");
    delete e.valueFrom;
    e.value = storeSecret(t).stringData.LIMN_JOB_STORE;
  }],
  ["an optional job store", "secretKeyRef must not be optional", (t) => { envOf(server(t), "LIMN_JOB_STORE").valueFrom.secretKeyRef.optional = true; }],
  ["a job store from a Secret no manifest defines", "names Secret limn-job-stor,", (t) => { envOf(server(t), "LIMN_JOB_STORE").valueFrom.secretKeyRef.name = "limn-job-stor"; }],
  ["a job store key the Secret lacks", "has no key JOB_STORE", (t) => { envOf(server(t), "LIMN_JOB_STORE").valueFrom.secretKeyRef.key = "JOB_STORE"; }],
  ["a job store Secret its kustomization does not apply", "is not applied by kustomization.yaml", (t) => { top(t).obj.resources = top(t).obj.resources.filter((r) => r !== "job-store-secret.yaml"); }],
  ["a SQLite job store for several replicas", "LIMN_JOB_STORE is a SQLite file", (t) => { storeSecret(t).stringData.LIMN_JOB_STORE = "sqlite:/var/lib/limn/data/jobs.sqlite"; }],
  ["a job store URI limn refuses", "is not a postgresql:// URI", (t) => { storeSecret(t).stringData.LIMN_JOB_STORE = "mysql://limn@limn-postgres/limn"; }],
  ["a job store at another host", "points at limn-postgress, not at the Service", (t) => setStoreUri(t, (u) => { u.hostname = "limn-postgress"; })],
  ["a job store on another port", "port 5433 is not a port of Service limn-postgres", (t) => setStoreUri(t, (u) => { u.port = "5433"; })],
  ["a job store with another password", "password is not the database's POSTGRES_PASSWORD", (t) => setStoreUri(t, (u) => { u.password = "another"; })],
  ["a job store with another role", "role limm is not the database's POSTGRES_USER", (t) => setStoreUri(t, (u) => { u.username = "limm"; })],
  ["a job store in another database", "database limm is not the database's POSTGRES_DB", (t) => setStoreUri(t, (u) => { u.pathname = "/limm"; })],
  ["replicas sharing one name", "LIMN_REPLICA must be the pod's name", (t) => {
    const e = envOf(server(t), "LIMN_REPLICA");
    delete e.valueFrom;
    e.value = "limn";
  }],
  ["two database pods", "replicas 2: PostgreSQL here is one primary", (t) => { database(t).spec.replicas = 2; }],
  ["a database without its claim", "is not on a volumeClaimTemplate", (t) => { database(t).spec.volumeClaimTemplates[0].metadata.name = "pgdata"; }],
  ["PGDATA at the volume's root", "must be a directory below the volume's root", (t) => { envOf(databaseContainer(t), "PGDATA").value = "/var/lib/postgresql/data"; }],
  ["a database ready before it answers", "no readinessProbe running pg_isready", (t) => { delete databaseContainer(t).readinessProbe; }],
  ["a database Service that selects nothing", "(Service limn-postgres): selector", (t) => { find(t, "Service", "limn-postgres").spec.selector["app.kubernetes.io/component"] = "job-stor"; }],
  ["a database Service with a cluster IP", "must be headless", (t) => { delete find(t, "Service", "limn-postgres").spec.clusterIP; }],
  ["a StatefulSet naming no Service", "serviceName limn-postgre names no Service", (t) => { database(t).spec.serviceName = "limn-postgre"; }],
  ["PGDATA made group-writable at every start", "fsGroupChangePolicy must be OnRootMismatch", (t) => { podSpecOf(database(t)).securityContext.fsGroupChangePolicy = "Always"; }],
  ["a database password in the pod spec", "POSTGRES_PASSWORD must come from a Secret", (t) => {
    const e = envOf(databaseContainer(t), "POSTGRES_PASSWORD");
    delete e.valueFrom;
    e.value = "secret";
  }],
  ["a database image that is not PostgreSQL", "is not PostgreSQL's (postgres)", (t) => { databaseContainer(t).image = "limn:0.1.0"; }],
];

async function runSelfTest(tree) {
  const baseErrors = await validate(tree);
  if (baseErrors.length) return fail(["the manifests themselves fail:", ...baseErrors]);
  const variants = breakages.map(([label, , breakIt]) => {
    const copy = structuredClone(tree);
    breakIt(copy);
    return { label, tree: copy, objects: copy.objects };
  });
  const types = typeErrors(variants);
  let missed = 0;
  for (const [label, expect] of breakages) {
    const v = variants.find((x) => x.label === label);
    const errors = [...(await validate(v.tree)), ...types.get(label)];
    const hit = errors.find((e) => e.includes(expect));
    if (hit) console.log(`validate-k8s: self-test: caught ${label}: ${hit}`);
    else {
      missed++;
      console.error(`validate-k8s: self-test: MISSED ${label} (wanted an error with ${JSON.stringify(expect)}); got:\n  ${errors.join("\n  ") || "no error"}`);
    }
  }
  if (missed) return fail([`${missed} of ${breakages.length} breakages went unnoticed`]);
  console.log(`validate-k8s: self-test: all ${breakages.length} breakages caught`);
}

function fail(lines) {
  for (const l of lines) console.error(`validate-k8s: ${l}`);
  process.exitCode = 1;
}

const tree = load(manifestDir);
if (selfTest) {
  await runSelfTest(tree);
} else {
  const errors = [...(await validate(tree)), ...typeErrors([{ label: "manifests", objects: tree.objects }]).get("manifests")];
  if (errors.length) fail([`${errors.length} problem(s) in ${path.relative(process.cwd(), manifestDir) || "."}:`, ...errors.map((e) => "  " + e)]);
  else {
    const kinds = tree.objects.map((o) => o.obj.kind).join(", ");
    console.log(`validate-k8s: ${tree.objects.length} objects valid (${kinds}) in ${tree.kustomizations.length} kustomizations`);
  }
}
