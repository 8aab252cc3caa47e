// Validates Kubernetes objects against the API schemas of the npm packages
// kubernetes-models (the built-in kinds), @kubernetes-models/prometheus-operator
// and @kubernetes-models/cert-manager (their CRDs).
//
// usage: node validate_objects.js < objects.json
//   stdin: a JSON array of objects (as `kubectl kustomize` renders them).
//   stdout: one line per object, `ok KIND/NAME` or `FAIL KIND/NAME: ERROR`
//   (the first schema error, or the first field the schema does not have).
//   exit 0: all valid; 1: an object failed; 2: unusable input.
//
// The packages' validators (compiled JSON schemas) accept fields they do not
// know, which the API server refuses (strict field validation) or drops. So
// each object is validated through proxies that record which properties the
// validator read: a property of an object whose schema lists properties
// (the validator read some of them) that the validator never looked at is
// not in the schema. Free-form objects (maps, which the validator iterates,
// and untyped objects, which it does not enter) are not flagged.
"use strict";

const fs = require("fs");

// The package holding each API group's models (the module is
// PACKAGE/apiVersion); every other group is a built-in one.
const CRD_PACKAGES = {
  "monitoring.coreos.com": "@kubernetes-models/prometheus-operator",
  "cert-manager.io": "@kubernetes-models/cert-manager",
  "acme.cert-manager.io": "@kubernetes-models/cert-manager",
};
const BUILT_IN = "kubernetes-models";

function modelFor(apiVersion, kind) {
  const group = apiVersion.includes("/") ? apiVersion.split("/")[0] : "";
  const pkg = CRD_PACKAGES[group] || BUILT_IN;
  let module;
  try {
    module = require(`${pkg}/${apiVersion}`);
  } catch (e) {
    if (e.code === "MODULE_NOT_FOUND" || e.code === "ERR_PACKAGE_PATH_NOT_EXPORTED") {
      return { pkg, Model: null };
    }
    throw e;
  }
  return { pkg, Model: typeof module[kind] === "function" ? module[kind] : null };
}

// A copy of `value` whose objects record the properties read from them into
// `objects` (one entry per object: its JSON pointer, keys and reads).
function tracked(value, pointer, objects) {
  if (value === null || typeof value !== "object") return value;
  if (Array.isArray(value)) {
    return value.map((item, i) => tracked(item, `${pointer}/${i}`, objects));
  }
  const entry = { pointer, keys: Object.keys(value), read: new Set() };
  objects.push(entry);
  const copy = {};
  for (const key of entry.keys) {
    copy[key] = tracked(value[key], `${pointer}/${key}`, objects);
  }
  return new Proxy(copy, {
    get(target, property, receiver) {
      if (typeof property === "string") entry.read.add(property);
      return Reflect.get(target, property, receiver);
    },
  });
}

function unknownField(objects) {
  for (const entry of objects) {
    if (entry.read.size === 0) continue;  // free-form: never entered
    for (const key of entry.keys) {
      if (!entry.read.has(key)) return `${entry.pointer}/${key}`;
    }
  }
  return null;
}

// The first problem of `object`, or null.
function check(object) {
  if (object === null || typeof object !== "object" || Array.isArray(object)) {
    return "not an object";
  }
  const { apiVersion, kind } = object;
  if (typeof apiVersion !== "string" || typeof kind !== "string") {
    return "no apiVersion or kind";
  }
  const { pkg, Model } = modelFor(apiVersion, kind);
  if (Model === null) {
    return `no schema for apiVersion ${apiVersion} kind ${kind} in ${pkg}`;
  }
  const objects = [];
  const data = tracked(object, "", objects);
  try {
    // The model's validate() runs the schema on `this`.
    Model.prototype.validate.call(data);
  } catch (e) {
    const first = Array.isArray(e.errors) && e.errors.length > 0
      ? `data${e.errors[0].instancePath} ${e.errors[0].message}`
      : e.message;
    return `schema error: ${first}`;
  }
  const unknown = unknownField(objects);
  if (unknown !== null) return `unknown field ${unknown} (not in the ${kind} schema)`;
  return null;
}

function main() {
  let objects;
  try {
    objects = JSON.parse(fs.readFileSync(0, "utf8"));
  } catch (e) {
    console.error(`validate_objects: stdin is not JSON: ${e.message}`);
    return 2;
  }
  if (!Array.isArray(objects) || objects.length === 0) {
    console.error("validate_objects: expected a non-empty JSON array of objects");
    return 2;
  }
  let failed = 0;
  for (const object of objects) {
    const name = object && object.metadata && object.metadata.name;
    const label = `${object && object.kind}/${name}`;
    const problem = check(object);
    if (problem === null) {
      console.log(`ok ${label}`);
    } else {
      console.log(`FAIL ${label}: ${problem}`);
      failed += 1;
    }
  }
  return failed === 0 ? 0 : 1;
}

process.exitCode = main();
