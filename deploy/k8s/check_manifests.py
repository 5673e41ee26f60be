"""Checks every field of rendered manifests against the python3-kubernetes (22.6 = Kubernetes
1.22) models: unknown fields, wrong scalar types, missing required fields. Known newer fields
(gRPC probes, 1.24) are checked by hand."""
import sys, yaml, re
import kubernetes.client as kc

KIND_MODEL = {("v1","ConfigMap"):"V1ConfigMap",("v1","Service"):"V1Service",("apps/v1","Deployment"):"V1Deployment",
  ("apps/v1","StatefulSet"):"V1StatefulSet",("policy/v1","PodDisruptionBudget"):"V1PodDisruptionBudget",
  ("networking.k8s.io/v1","NetworkPolicy"):"V1NetworkPolicy"}
NEWER = {("V1Probe","grpc"): {"port": int, "service": str}}
errors = []
def check(obj, model, path):
    if model in ("str",): 
        if not isinstance(obj, str): errors.append(f"{path}: expected string, got {obj!r}")
        return
    if model == "int":
        if not isinstance(obj, int) or isinstance(obj,bool): errors.append(f"{path}: expected int, got {obj!r}")
        return
    if model == "bool":
        if not isinstance(obj, bool): errors.append(f"{path}: expected bool, got {obj!r}")
        return
    if model == "object": return
    m = re.match(r"list\[(.*)\]$", model)
    if m:
        if not isinstance(obj, list): errors.append(f"{path}: expected list"); return
        for i, x in enumerate(obj): check(x, m.group(1), f"{path}[{i}]")
        return
    m = re.match(r"dict\(str, (.*)\)$", model)
    if m:
        if not isinstance(obj, dict): errors.append(f"{path}: expected map"); return
        for k, v in obj.items(): check(v, m.group(1), f"{path}.{k}")
        return
    cls = getattr(kc, model, None)
    if cls is None: errors.append(f"{path}: unknown model {model}"); return
    if model == "IntOrString" or not hasattr(cls, "attribute_map"):
        return
    if not isinstance(obj, dict): errors.append(f"{path}: expected object {model}, got {obj!r}"); return
    rev = {v: k for k, v in cls.attribute_map.items()}
    for k, v in obj.items():
        if (model, k) in NEWER:
            for kk, vv in v.items():
                if kk not in NEWER[(model,k)] or not isinstance(vv, NEWER[(model,k)][kk]): errors.append(f"{path}.{k}.{kk}: bad")
            continue
        if k not in rev: errors.append(f"{path}.{k}: unknown field of {model}"); continue
        check(v, cls.openapi_types[rev[k]], f"{path}.{k}")
    # required: constructor raises on None for required fields
    import inspect
    src = inspect.getsource(cls)
    for attr, key in cls.attribute_map.items():
        if f"`{attr}`, must not be `None`" in src and key not in obj:
            errors.append(f"{path}: missing required {key} ({model})")
docs = [d for d in yaml.safe_load_all(open(sys.argv[1])) if d]
for d in docs:
    model = KIND_MODEL.get((d.get("apiVersion"), d.get("kind")))
    if not model: errors.append(f"no model for {d.get('apiVersion')} {d.get('kind')}"); continue
    check(d, model, f"{d['kind']}/{d['metadata']['name']}")
# cross references
names = {(d["kind"], d["metadata"]["name"]) for d in docs}
for d in docs:
    spec = d.get("spec", {})
    tpl = spec.get("template", {}).get("spec")
    if tpl:
        for v in tpl.get("volumes", []):
            if "configMap" in v and ("ConfigMap", v["configMap"]["name"]) not in names: errors.append(f"{d['metadata']['name']}: missing ConfigMap {v['configMap']['name']}")
        for c in tpl["containers"]:
            for e in c.get("env", []):
                r = e.get("valueFrom", {}).get("configMapKeyRef")
                if r:
                    cm = [x for x in docs if x["kind"]=="ConfigMap" and x["metadata"]["name"]==r["name"]]
                    if not cm or r["key"] not in cm[0]["data"]: errors.append(f"{d['metadata']['name']}: missing {r}")
            envs = {e["name"] for e in c.get("env", [])}
            for a in c.get("args", []) + c.get("command", []):
                for var in re.findall(r"\$\((\w+)\)", a):
                    if var not in envs: errors.append(f"{d['metadata']['name']}: $({var}) not in env")
        sel = spec["selector"]["matchLabels"]
        labels = spec["template"]["metadata"]["labels"]
        if any(labels.get(k) != v for k, v in sel.items()): errors.append(f"{d['metadata']['name']}: selector does not match template")
        if d["kind"] == "StatefulSet" and ("Service", spec["serviceName"]) not in names: errors.append(f"missing service {spec['serviceName']}")
    if d["kind"] == "Service":
        sel = spec["selector"]
        if not any(x["kind"] in ("Deployment","StatefulSet") and all(x["spec"]["template"]["metadata"]["labels"].get(k)==v for k,v in sel.items()) for x in docs):
            errors.append(f"Service {d['metadata']['name']} selects no pods")
        for p in spec["ports"]:
            tp = p.get("targetPort")
            if isinstance(tp, str):
                ok = any(tp in [cp.get("name") for c in x["spec"]["template"]["spec"]["containers"] for cp in c.get("ports", [])] for x in docs if x["kind"] in ("Deployment","StatefulSet") and all(x["spec"]["template"]["metadata"]["labels"].get(k)==v for k,v in sel.items()))
                if not ok: errors.append(f"Service {d['metadata']['name']}: targetPort {tp} not a named container port")
print(f"{len(docs)} objects checked")
for e in errors: print("ERROR", e)
sys.exit(1 if errors else 0)
