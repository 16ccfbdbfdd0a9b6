"""Prints the test executables of one crate from cargo's JSON messages of a test build
(`cargo test --no-run --message-format=json`), one per line: the harnesses (profile.test) of
the crate in FOLDER, or only its integration test TEST. Exits 1 when there is none.

Usage: python3 scripts/test-executables.py MESSAGES FOLDER [TEST]   (MESSAGES: a file or -)
"""
import json
import sys

path, folder = sys.argv[1], sys.argv[2]
test = sys.argv[3] if len(sys.argv) > 3 else None
found = 0
for line in sys.stdin if path == "-" else open(path):
    m = json.loads(line)
    if (m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]
            and m["manifest_path"].endswith(f"/{folder}/Cargo.toml")
            and (test is None or (m["target"]["name"] == test and m["target"]["kind"] == ["test"]))):
        print(m["executable"])
        found += 1
if not found:
    sys.exit(f"no test executable {test or ''} of {folder}/ in {path}")
