#!/usr/bin/python3
"""Checks real answers of limn against its OpenAPI document (api/openapi.json).

Usage: check_openapi.py OPENAPI_JSON ANSWER_DIR
ANSWER_DIR holds pairs NAME.meta (one line: METHOD PATH STATUS CONTENT-TYPE) and NAME.body.
Each answer's status must be declared for its operation, its media type declared for that
status, and a JSON body must validate against the declared schema - strictly: an object
schema with properties admits no property it does not describe, so a field the server sends
but the document lacks fails too. Prints one line per problem; exits 1 when there is any.
OpenAPI 3.0 schemas are JSON Schema draft 4 plus `nullable`, which is rewritten here."""
import copy
import json
import os
import sys

import jsonschema


def strict(schema):
    """Rewrites OpenAPI 3.0 schema objects into strict JSON Schema draft 4."""
    if isinstance(schema, list):
        return [strict(s) for s in schema]
    if not isinstance(schema, dict):
        return schema
    out = {k: strict(v) for k, v in schema.items()}
    if out.pop("nullable", False):
        if "type" in out:
            out["type"] = [out["type"], "null"]
        else:
            out = {"anyOf": [out, {"type": "null"}]}
    if "properties" in out and "additionalProperties" not in out:
        out["additionalProperties"] = False
    return out


def main():
    document = json.load(open(sys.argv[1], encoding="utf-8"))
    root = strict(copy.deepcopy(document))
    resolver = jsonschema.RefResolver.from_schema(root)
    problems = 0
    checked = 0
    folder = sys.argv[2]
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".meta"):
            continue
        method, path, status, content_type = open(os.path.join(folder, name)).read().split(" ", 3)
        content_type = content_type.strip().split(";")[0]
        body = open(os.path.join(folder, name[:-5] + ".body"), "rb").read()
        where = f"{method} {path} -> {status} ({name[:-5]})"
        operations = document["paths"].get(path, {})
        operation = operations.get(method.lower())
        if operation is None and status == "405":
            # A method the path does not have: its 405 is declared on the operations it has.
            operation = next((o for o in operations.values() if "405" in o.get("responses", {})), None)
        if operation is None:
            print(f"{where}: the document has no such operation")
            problems += 1
            continue
        responses = operation["responses"]
        response = responses.get(status) or responses.get("default")
        if response is None:
            print(f"{where}: status {status} is not declared (declared: {', '.join(responses)})")
            problems += 1
            continue
        content = response.get("content", {})
        if content_type not in content:
            print(f"{where}: media type {content_type} is not declared (declared: {', '.join(content)})")
            problems += 1
            continue
        checked += 1
        schema = strict(content[content_type].get("schema"))
        if content_type != "application/json" or schema is None:
            continue
        validator = jsonschema.Draft4Validator(schema, resolver=resolver)
        for error in sorted(validator.iter_errors(json.loads(body)), key=lambda e: list(e.path)):
            location = "/".join(str(p) for p in error.absolute_path) or "(root)"
            print(f"{where}: at {location}: {error.message[:300]}")
            problems += 1
    print(f"{checked} answers checked, {problems} problems")
    sys.exit(1 if problems or checked == 0 else 0)


main()
