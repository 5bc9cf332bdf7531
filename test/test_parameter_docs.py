"""Every parameter in config/*.yaml carries a one-line comment with its unit and is documented in
doc/parameters.md."""
import glob
import os
import re
import unittest

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
KEY = re.compile(r"^([a-z_][a-z0-9_]*):")


class ParameterDocsTest(unittest.TestCase):
    def setUp(self):
        self.readme = open(os.path.join(PKG, "doc", "parameters.md"), encoding="utf-8").read()
        self.files = sorted(glob.glob(os.path.join(PKG, "config", "*.yaml")))
        self.assertGreaterEqual(len(self.files), 2)

    def test_every_parameter_has_a_unit_comment(self):
        for path in self.files:
            for n, line in enumerate(open(path, encoding="utf-8"), 1):
                if KEY.match(line):
                    self.assertRegex(line, r"#\s*\[[^\]]+\]\s*\S", "%s:%d has no '# [unit] comment'" % (path, n))

    def test_every_parameter_is_in_the_parameter_doc(self):
        missing = []
        for path in self.files:
            for line in open(path, encoding="utf-8"):
                m = KEY.match(line)
                if m and "`%s`" % m.group(1) not in self.readme:
                    missing.append("%s: %s" % (os.path.basename(path), m.group(1)))
        self.assertEqual(missing, [])


if __name__ == "__main__":
    unittest.main()
