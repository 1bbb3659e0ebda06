// Validates every manifest in deploy/k8s/*.yaml against the Kubernetes and prometheus-operator
// JSON schemas bundled by kubernetes-models (offline: no cluster, no download at run time), and
// checks what the schemas cannot: the Envoy configuration in its ConfigMap parses, hashes on the
// handle header and routes to the galpha Service; probes and ports agree with the server's flags.
// Exits 1 naming every problem.
import { readFileSync, readdirSync } from "node:fs";
import { join, dirname } from "node:path";
import { fileURLToPath } from "node:url";
import { parseAllDocuments, parse } from "yaml";

const here = dirname(fileURLToPath(import.meta.url));
const manifests = join(here, "..");

// apiVersion/kind -> the model's module and class name.
function modelPath(apiVersion, kind) {
  if (apiVersion === "monitoring.coreos.com/v1") {
    return `@kubernetes-models/prometheus-operator/monitoring.coreos.com/v1/${kind}`;
  }
  const [group, version] = apiVersion.includes("/") ? apiVersion.split("/") : ["", apiVersion];
  return group === "" ? `kubernetes-models/${version}/${kind}` : `kubernetes-models/${group}/${version}/${kind}`;
}

const problems = [];
const objects = [];
for (const file of readdirSync(manifests).filter((f) => f.endsWith(".yaml")).sort()) {
  const documents = parseAllDocuments(readFileSync(join(manifests, file), "utf8"));
  for (const document of documents) {
    if (document.errors.length > 0) {
      problems.push(`${file}: YAML: ${document.errors.map((e) => e.message).join("; ")}`);
      continue;
    }
    const object = document.toJS();
    if (object === null) continue;
    const where = `${file}: ${object.kind}/${object.metadata?.name}`;
    let Model;
    try {
      const module = await import(modelPath(object.apiVersion, object.kind));
      Model = module[object.kind] ?? module.default;
    } catch (error) {
      problems.push(`${where}: no schema for ${object.apiVersion} ${object.kind}`);
      continue;
    }
    try {
      new Model(object).validate();
      objects.push({ file, object });
      console.log(`ok  ${where}`);
    } catch (error) {
      problems.push(`${where}: ${error.message}`);
    }
  }
}

// What the schemas cannot see.
const find = (kind, name) => objects.find((o) => o.object.kind === kind && o.object.metadata.name === name)?.object;
const server = find("Deployment", "galpha");
if (!server) problems.push("no Deployment galpha");
else {
  const container = server.spec.template.spec.containers[0];
  const args = container.args.join(" ");
  const flag = (name) => Number((args.match(new RegExp(`--${name}=(\\d+)`)) || [])[1]);
  const notice = flag("drain_notice_ms"), grace = flag("drain_grace_ms");
  const period = server.spec.template.spec.terminationGracePeriodSeconds;
  if (!(period * 1000 > notice + grace)) {
    problems.push(`terminationGracePeriodSeconds ${period} s must exceed the drain (${notice} + ${grace} ms)`);
  }
  if (container.resources.limits["nvidia.com/gpu"] !== 1) problems.push("the server must request exactly one GPU");
  const grpcPort = container.ports.find((p) => p.name === "grpc").containerPort;
  for (const probe of ["readinessProbe", "livenessProbe", "startupProbe"]) {
    if (container[probe]?.grpc?.port !== grpcPort) problems.push(`${probe} must be a gRPC probe on port ${grpcPort}`);
  }
  if (!args.includes(`--listen=0.0.0.0:${grpcPort}`)) problems.push(`--listen must use the grpc port ${grpcPort}`);
}
const envoyConfig = find("ConfigMap", "galpha-envoy");
if (!envoyConfig) problems.push("no ConfigMap galpha-envoy");
else {
  try {
    const envoy = parse(envoyConfig.data["envoy.yaml"]);
    const cluster = envoy.static_resources.clusters.find((c) => c.name === "galpha");
    if (cluster?.lb_policy !== "RING_HASH") problems.push("Envoy's galpha cluster must use RING_HASH");
    const address = cluster.load_assignment.endpoints[0].lb_endpoints[0].endpoint.address.socket_address;
    const service = find("Service", "galpha");
    if (address.address !== `galpha.${service.metadata.namespace}.svc.cluster.local`) {
      problems.push(`Envoy resolves ${address.address}, not the galpha Service`);
    }
    if (service.spec.clusterIP !== "None") problems.push("the galpha Service must be headless for the ring hash");
    const routes = envoy.static_resources.listeners[0].filter_chains[0].filters[0].typed_config.route_config
      .virtual_hosts[0].routes;
    const api = routes.find((r) => r.match.prefix === "/galpha.v1.AlphaShapes/");
    if (api?.route?.hash_policy?.[0]?.header?.header_name !== "x-galpha-handle") {
      problems.push("Envoy must hash AlphaShapes calls on the x-galpha-handle header");
    }
  } catch (error) {
    problems.push(`the Envoy configuration does not parse as expected: ${error.message}`);
  }
}

if (problems.length > 0) {
  for (const p of problems) console.error(`FAIL ${p}`);
  process.exit(1);
}
console.log(`all ${objects.length} manifests valid`);
