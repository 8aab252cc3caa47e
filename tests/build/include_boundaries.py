#!/usr/bin/python3
"""Which of the project's files reach LibTorch's headers, and through what.

  tests/build/include_boundaries.py [--root DIR] [--allowed FILE]
      [--explain PATH | --list LEVEL]

Follows the project's own #include graph (quoted and <...> includes that
name a file of the tree; proto/X.pb.h stands for the generated header of
proto/X.proto) from every .h and .cc under the source folders, and gives
each file the heaviest LibTorch level it reaches:

  torch   <torch/...>, or any <ATen/...> or <c10/...> header other than the
          tensor class: the module API, the operators, c10d. Tens of
          seconds of parsing in every translation unit that reaches it.
  tensor  <ATen/core/Tensor.h> (or <c10/...> alone): the at::Tensor class
          that data structures hold. Several seconds per translation unit.

Every file may reach at most the level its first matching pattern in the
allowed list grants (fnmatch patterns over paths relative to the root;
unlisted files: none). Exits 1 listing each file over its level with the
include chain that brings the header in; --explain PATH prints the chain of
one file; --list LEVEL prints the .cc files that reach LEVEL, one per line
(the build precompiles LibTorch's headers for those that reach torch).
"""

import argparse
import fnmatch
import os
import re
import sys

SOURCE_DIRS = ("proto", "common", "actor", "learner", "deploy", "bench",
               "tests")
LEVELS = {"none": 0, "tensor": 1, "torch": 2}
TENSOR_HEADERS = ("ATen/core/Tensor.h",)
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def header_level(name):
    """The LibTorch level of a header outside the project, by its name."""
    if name in TENSOR_HEADERS:
        return LEVELS["tensor"]
    if name.startswith("c10/") and not name.startswith("c10/distributed"):
        return LEVELS["tensor"]
    if name.startswith(("torch/", "ATen/", "c10d/", "c10/distributed")):
        return LEVELS["torch"]
    return LEVELS["none"]


def read_allowed(path):
    """[(pattern, level)] in file order; '#' starts a comment."""
    rules = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            words = line.split()
            if len(words) != 2 or words[1] not in LEVELS:
                raise SystemExit(f"{path}:{number}: expected 'PATTERN "
                                 f"none|tensor|torch', got '{line}'")
            rules.append((words[0], LEVELS[words[1]]))
    return rules


def allowed_level(rules, path):
    for pattern, level in rules:
        if fnmatch.fnmatchcase(path, pattern):
            return level
    return LEVELS["none"]


class IncludeGraph:
    """The project's files and the includes of each, resolved."""

    def __init__(self, root):
        self.root = root
        self.files = []
        for folder in SOURCE_DIRS:
            for directory, subdirs, names in os.walk(os.path.join(root, folder)):
                subdirs[:] = sorted(d for d in subdirs if d != "corpus")
                for name in sorted(names):
                    if name.endswith((".h", ".cc", ".proto")):
                        self.files.append(os.path.relpath(
                            os.path.join(directory, name), root))
        self.known = set(self.files)
        self._includes = {}
        self._reach = {}

    def includes(self, path):
        """[(name, project file or None)] of the #include lines of path."""
        if path not in self._includes:
            found = []
            if path.endswith(".cc") or path.endswith(".h"):
                with open(os.path.join(self.root, path), errors="replace") as f:
                    for line in f:
                        match = INCLUDE.match(line)
                        if match:
                            found.append((match.group(2),
                                          self.resolve(path, match.group(2))))
            self._includes[path] = found
        return self._includes[path]

    def resolve(self, including, name):
        # Generated protobuf and gRPC headers stand for their .proto: they
        # include only protobuf's and gRPC's headers (and each other).
        generated = re.match(r"^(proto/\w+)\.(grpc\.)?pb\.h$", name)
        if generated and generated.group(1) + ".proto" in self.known:
            return generated.group(1) + ".proto"
        for candidate in (name, os.path.join(os.path.dirname(including), name)):
            candidate = os.path.normpath(candidate)
            if candidate in self.known:
                return candidate
        return None

    def reach(self, path):
        """(level, chain): the heaviest level path reaches and one chain of
        includes to a header of that level (path first, the header last)."""
        if path in self._reach:
            return self._reach[path]
        self._reach[path] = (0, [path])  # an include cycle adds nothing
        best = (0, [path])
        for name, target in self.includes(path):
            if target is None:
                level, chain = header_level(name), [f"<{name}>"]
            else:
                level, chain = self.reach(target)
            if level > best[0]:
                best = (level, [path] + chain)
        self._reach[path] = best
        return best


def violations(root, rules):
    graph = IncludeGraph(root)
    found = []
    for path in graph.files:
        if path.endswith(".proto"):
            continue
        level, chain = graph.reach(path)
        limit = allowed_level(rules, path)
        if level > limit:
            found.append((path, level, limit, chain))
    return found


def level_name(level):
    return next(name for name, value in LEVELS.items() if value == level)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))  # tests/build/ -> the repo
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=root)
    parser.add_argument("--allowed", default=os.path.join(here, "torch_users.txt"))
    parser.add_argument("--explain", metavar="PATH")
    parser.add_argument("--list", choices=sorted(LEVELS), metavar="LEVEL")
    args = parser.parse_args()
    if args.list:
        graph = IncludeGraph(args.root)
        for path in graph.files:
            if path.endswith(".cc") and graph.reach(path)[0] >= LEVELS[args.list]:
                print(path)
        return 0
    rules = read_allowed(args.allowed)
    if args.explain:
        graph = IncludeGraph(args.root)
        if args.explain not in graph.known:
            print(f"include_boundaries.py: {args.explain} is not a source "
                  f"file under {args.root}", file=sys.stderr)
            return 2
        level, chain = graph.reach(args.explain)
        print(f"{args.explain}: reaches {level_name(level)} (allowed: "
              f"{level_name(allowed_level(rules, args.explain))})")
        print("  " + " -> ".join(chain))
        return 0
    found = violations(args.root, rules)
    for path, level, limit, chain in found:
        print(f"{path}: reaches {level_name(level)}, allowed "
              f"{level_name(limit)}: " + " -> ".join(chain))
    if found:
        print(f"include_boundaries.py: {len(found)} files reach more of "
              f"LibTorch than {os.path.relpath(args.allowed, args.root)} "
              "allows them: include a lighter header (a forward declaration, "
              "a config or stats header) or, for network and learning code, "
              "extend the list", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
