#!/usr/bin/python3
"""Tests of tests/build/include_boundaries.py, and the check itself on the
project's tree (the allowed list in tests/build/torch_users.txt).

  /usr/bin/python3 tests/build/include_boundaries_test.py
"""

import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SCRIPT = os.path.join(HERE, "include_boundaries.py")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True,
                          text=True, check=False)


class ProjectTreeTest(unittest.TestCase):

    def test_no_file_reaches_more_of_libtorch_than_allowed(self):
        result = run("--root", REPO)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)

    def test_the_run_configuration_compiles_without_libtorch(self):
        for path in ("deploy/run/run_config.h", "deploy/run/run_config.cc",
                     "learner/run/progress_columns.h", "learner/run/run_directory.h",
                     "learner/learner_config.h", "proto/wire_format.h"):
            result = run("--root", REPO, "--explain", path)
            self.assertEqual(result.returncode, 0, result.stderr)
            expected = "tensor" if path == "proto/wire_format.h" else "none"
            self.assertIn(f"reaches {expected} ", result.stdout)


class CheckerTest(unittest.TestCase):

    def setUp(self):
        self.root = tempfile.mkdtemp()
        self.allowed = os.path.join(self.root, "allowed.txt")
        self.addCleanup(shutil.rmtree, self.root)

    def write(self, path, text):
        full = os.path.join(self.root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w") as f:
            f.write(text)

    def check(self, allowed):
        with open(self.allowed, "w") as f:
            f.write(allowed)
        return run("--root", self.root, "--allowed", self.allowed)

    def test_a_chain_through_project_headers_is_reported(self):
        self.write("learner/core.h", "#include <torch/nn/module.h>\n")
        self.write("deploy/stats.h", '#include "learner/core.h"\n')
        self.write("deploy/report.cc", '#include "deploy/stats.h"\n')
        result = self.check("learner/* torch\n")
        self.assertEqual(result.returncode, 1)
        self.assertIn("deploy/report.cc: reaches torch, allowed none: "
                      "deploy/report.cc -> deploy/stats.h -> learner/core.h "
                      "-> <torch/nn/module.h>", result.stdout)
        self.assertIn("deploy/stats.h: reaches torch", result.stdout)
        self.assertNotIn("learner/core.h:", result.stdout)

    def test_the_tensor_class_is_a_level_of_its_own(self):
        self.write("common/segment.h", "#include <ATen/core/Tensor.h>\n")
        self.write("common/ops.cc", "#include <ATen/ATen.h>\n")
        self.write("deploy/a.cc", '#include "common/segment.h"\n')
        result = self.check("deploy/* tensor\ncommon/* tensor\n")
        self.assertEqual(result.returncode, 1)
        self.assertIn("common/ops.cc: reaches torch, allowed tensor",
                      result.stdout)
        self.assertNotIn("deploy/a.cc", result.stdout)
        self.assertNotIn("common/segment.h", result.stdout)

    def test_the_first_matching_pattern_decides(self):
        self.write("learner/config.h", '#include "learner/core.h"\n')
        self.write("learner/core.h", "#include <torch/torch.h>\n")
        result = self.check("learner/config.h none\nlearner/* torch\n")
        self.assertEqual(result.returncode, 1)
        self.assertIn("learner/config.h: reaches torch, allowed none",
                      result.stdout)

    def test_generated_protobuf_headers_stand_for_their_proto(self):
        self.write("proto/run.proto", 'syntax = "proto3";\n')
        self.write("deploy/a.cc", '#include "proto/run.pb.h"\n'
                   '#include "proto/run.grpc.pb.h"\n')
        self.assertEqual(self.check("").returncode, 0)

    def test_include_cycles_end(self):
        self.write("common/a.h", '#include "common/b.h"\n')
        self.write("common/b.h", '#include "common/a.h"\n#include <c10/x.h>\n')
        result = self.check("")
        self.assertEqual(result.returncode, 1)
        self.assertIn("common/a.h: reaches tensor", result.stdout)

    def test_list_names_the_sources_that_reach_a_level(self):
        self.write("common/ops.h", "#include <ATen/ATen.h>\n")
        self.write("common/ops.cc", '#include "common/ops.h"\n')
        self.write("common/tensor.cc", "#include <ATen/core/Tensor.h>\n")
        self.write("deploy/plain.cc", "#include <string>\n")
        torch = run("--root", self.root, "--list", "torch")
        self.assertEqual(torch.stdout.split(), ["common/ops.cc"])
        tensor = run("--root", self.root, "--list", "tensor")
        self.assertEqual(tensor.stdout.split(),
                         ["common/ops.cc", "common/tensor.cc"])

    def test_a_malformed_allowed_list_is_refused_with_its_line(self):
        self.write("common/a.h", "\n")
        result = self.check("common/* everything\n")
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("allowed.txt:1: expected 'PATTERN none|tensor|torch'",
                      result.stderr)


if __name__ == "__main__":
    unittest.main()
