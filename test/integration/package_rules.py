#!/usr/bin/python3
"""rostest (package_rules.test): the dependency rules of DESIGN.md ("Which package may depend on
which"), checked on every package.xml of the repository and on the sources they cover. Pure
Python: no node (rostest's master is not used)."""
import glob
import os
import re
import subprocess
import unittest
import xml.etree.ElementTree as ET

import rostest

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", ".."))
ALGORITHMS = ("lfd_segmentation", "lfd_dmp")
ROBOTS = ("_description",)  # a robot package's name ends so (DESIGN.md, "Adding a robot")


def manifests():
    """{package: (folder, {dependency: set of kinds})} for every package.xml under git."""
    files = subprocess.run(["git", "ls-files", "*package.xml"], cwd=ROOT, check=True,
                           capture_output=True, text=True).stdout.split()
    out = {}
    for f in files:
        tree = ET.parse(os.path.join(ROOT, f)).getroot()
        deps = {}
        for e in tree:
            if e.tag.endswith("depend") and e.tag != "buildtool_depend":
                deps.setdefault(e.text.strip(), set()).add(e.tag)
        out[tree.find("name").text.strip()] = (os.path.dirname(f), deps)
    return out


ROS_INCLUDE = re.compile(
    r'#include\s*[<"](ros/|rosbag/|topic_tools/|actionlib|tf2|[a-z_]+_msgs/|lfd_msgs/|lfd_ros/)')
LOCAL_INCLUDE = re.compile(r'#include\s*"([^"]+)"')


def repository_header(name, including_file):
    """The repository file an #include "name" resolves to (next to the including file, or in a
    package's include/ folder), or None for a system header."""
    candidates = [os.path.join(os.path.dirname(including_file), name)]
    package = name.split("/")[0]
    candidates.append(os.path.join(ROOT, package, "include", name))
    for c in candidates:
        if os.path.isfile(c):
            return os.path.realpath(c)
    return None


def ros_includes(path, seen):
    """["file: #include ..."] for every ROS header path includes, directly or through the
    repository's own headers."""
    path = os.path.realpath(path)
    if path in seen:
        return []
    seen.add(path)
    text = open(path, errors="replace").read()
    found = ["%s: %s" % (os.path.relpath(path, ROOT), m.group(0))
             for m in ROS_INCLUDE.finditer(text)]
    for m in LOCAL_INCLUDE.finditer(text):
        header = repository_header(m.group(1), path)
        if header:
            found += ros_includes(header, seen)
    return found


def is_robot(name):
    return name.endswith(ROBOTS)


def runtime(deps):
    """The dependencies beyond the tests'."""
    return {d for d, kinds in deps.items() if kinds != {"test_depend"}}


class PackageRules(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.packages = manifests()
        cls.lfd = {p for p in cls.packages}

    def deps_of(self, package):
        self.assertIn(package, self.packages, "no package.xml names %s" % package)
        return self.packages[package][1]

    def test_the_core_depends_on_no_ros_package(self):
        keys = os.path.join(ROOT, ".ci", "rosdep-keys.txt")
        system = {line.split()[0] for line in open(keys) if line.strip() and line[0] != "#"}
        system.add("urdfdom")  # a plain C++ library, which Debian ships with a package.xml
        bad = {d for d in runtime(self.deps_of("lfd_core"))
               if d not in system and not is_robot(d)}
        self.assertEqual(bad, set(), "lfd_core stays ROS-free (robots: its benchmarks' data)")

    def test_the_core_sources_include_no_ros_header(self):
        folder = os.path.join(ROOT, self.packages["lfd_core"][0])
        found = []
        for sub in ("include", "lib"):
            for path in glob.glob(os.path.join(folder, sub, "**", "*.[ch]pp"), recursive=True):
                found += ros_includes(path, set())
        self.assertEqual(found, [])

    def test_every_lib_folder_is_ros_free(self):
        """DESIGN.md's layout: a package's lib/ holds no ROS code (that is ros/), neither in its
        sources nor in the repository headers they include, at any depth."""
        folders = [self.packages[p][0] for p in sorted(self.packages)]
        checked, found = 0, []
        for folder in folders:
            for path in glob.glob(os.path.join(ROOT, folder, "lib", "**", "*.*"), recursive=True):
                if path.endswith((".cpp", ".hpp", ".h", ".inc")):
                    checked += 1
                    found += ros_includes(path, set())
        self.assertGreater(checked, 50, "no lib/ sources found under %s" % ROOT)
        self.assertEqual(found, [])

    def test_algorithms_know_no_simulator_and_no_robot(self):
        for package in ALGORITHMS:
            deps = runtime(self.deps_of(package))
            self.assertNotIn("lfd_sim_bridge", deps, package)
            self.assertEqual({d for d in deps if is_robot(d)}, set(), package)

    def test_segmentation_does_not_use_the_dmp_package(self):
        self.assertNotIn("lfd_dmp", self.deps_of("lfd_segmentation"))

    def test_the_simulator_does_not_use_the_algorithms(self):
        deps = self.deps_of("lfd_sim_bridge")
        self.assertEqual({d for d in deps if d in ALGORITHMS}, set())

    def test_data_and_base_packages_depend_on_no_lfd_package(self):
        for package, (_, deps) in self.packages.items():
            if package in ("lfd_config", "lfd_msgs") or is_robot(package):
                self.assertEqual({d for d in deps if d in self.lfd}, set(), package)
        # lfd_ros: the ROS side of lfd_core's readers and budgets, for every node
        self.assertEqual({d for d in self.deps_of("lfd_ros") if d in self.lfd}, {"lfd_core"})

    def test_no_cycle_between_lfd_packages(self):
        graph = {p: {d for d in deps if d in self.lfd} for p, (_, deps) in self.packages.items()}
        state = {}

        def visit(p, path):
            if state.get(p) == "done":
                return
            self.assertNotEqual(state.get(p), "open", "cycle: " + " -> ".join(path + [p]))
            state[p] = "open"
            for d in graph[p]:
                visit(d, path + [p])
            state[p] = "done"
        for p in graph:
            visit(p, [])

    def test_no_source_includes_across_folders(self):
        out = subprocess.run(["git", "grep", "-n", '#include "\\.\\./', "--", "*.cpp", "*.hpp",
                              "*.h"], cwd=ROOT, capture_output=True, text=True).stdout
        self.assertEqual(out, "", "shared test helpers come through lfd_test_support")


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "package_rules", PackageRules)
