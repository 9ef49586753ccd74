#!/usr/bin/python3
"""rostest (results_doc_units.test): docs/results.md's generated sections (lfd_tools.results_doc).
A small pipeline report rewrites the pipeline's sections of a small document and nothing else
(byte for byte outside them; a second update changes nothing); a missing, unclosed or repeated
marker is an error that names the section and the marker lines, and leaves the file as it was;
each benchmark's result renders its section; the command line takes KIND=FILE; the committed
docs/results.md holds every section of every source. Pure Python: no node (rostest's master is
not used)."""
import json
import os
import tempfile
import unittest

import rostest
from lfd_tools import report_tables, results_doc

MADE_BY = "*made by the test*"


def goal(goal_id, success, error_m):
    return {"id": goal_id, "success": success, "object_position_error_m": error_m,
            "monitored": False, "max_anomaly_score": None, "monitor_alarm": ""}


REPORT = {
    "robot": "jvrc1",
    "datasets": {"sim_grasp": {"demos": 3}, "teleop_grasp": {"demos": 2}},
    "segmentation": {"sim_grasp": {"tolerance_s": 0.5, "selected_features": ["/ee_pose/z"],
                                   "methods": {"weighted_product": 1.0, "average": 2 / 3.0}}},
    "learning": {"sim_grasp": {"segments": 2, "expected_segments": 2, "demos_used": 3,
                               "changepoint_counts": [1, 1, 1], "warnings": []}},
    "reproduction": {"grasp": {"goals": [goal(100, True, 0.0012), goal(101, False, 0.05)],
                               "execution_time_ratio": 0.99,
                               "mean_object_position_error_m": 0.0256,
                               "mean_tcp_position_error_m": 0.0002}},
    "timings": {"datasets_s": 10.0, "segment_s": 2.0, "total_s": 12.0},
    "problems": [],
}
PIPELINE = ("pipeline-run", "pipeline-segmentation", "pipeline-learning", "pipeline-reproduction")
BEFORE = "# Results\n\nHand-written text, kept.\n\n"
BETWEEN = "\n\nMore hand-written text | with a | table-like line.\n\n"
AFTER = "\n\nThe end, kept too.\n"


def section(name, inside="old figures\n| a | b |"):
    return "<!-- generated: %s -->\n%s\n<!-- end generated -->" % (name, inside)


def doc_text(names=PIPELINE):
    return BEFORE + BETWEEN.join(section(n) for n in names) + AFTER


class Sections(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.doc = os.path.join(self.tmp.name, "results.md")

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, text):
        with open(self.doc, "w") as f:
            f.write(text)

    def read(self):
        with open(self.doc) as f:
            return f.read()

    def test_the_sections_are_replaced_and_nothing_else(self):
        self.write(doc_text())
        changed = results_doc.update("pipeline", REPORT, self.doc, made_by=MADE_BY)
        self.assertEqual(sorted(changed), sorted(PIPELINE))
        text = self.read()
        expected = results_doc.render("pipeline", REPORT, MADE_BY)
        # outside the sections: the text as it was, byte for byte
        outside = text
        for name in PIPELINE:
            inside = "\n\n%s\n\n" % expected[name]
            self.assertIn(section(name, inside[1:-1]), text)
            outside = outside.replace(section(name, inside[1:-1]), "@")
        self.assertEqual(outside, BEFORE + BETWEEN.join("@" for _ in PIPELINE) + AFTER)
        self.assertNotIn("old figures", text)
        # a second update finds it current and writes nothing
        mtime = os.stat(self.doc).st_mtime_ns
        self.assertEqual(results_doc.update("pipeline", REPORT, self.doc, made_by=MADE_BY), [])
        self.assertEqual(self.read(), text)
        self.assertEqual(os.stat(self.doc).st_mtime_ns, mtime)

    def test_the_pipeline_sections_hold_the_reports_tables(self):
        sections = results_doc.render("pipeline", REPORT, MADE_BY)
        for name in PIPELINE:
            self.assertTrue(sections[name].startswith(MADE_BY + "\n"), name)
        run = sections["pipeline-run"]
        self.assertIn("robot jvrc1; 2 datasets, 5 demonstrations; 2 sim and 0 teleop goals "
                      "reproduced; no problems.", run)
        self.assertIn("| datasets | 10.0 s |", run)
        self.assertIn("| **total** | **12.0 s** |", run)
        # report.md's own tables (lfd_tools.report_tables), not a second rendering of them
        self.assertIn("\n".join(report_tables.segmentation_table(REPORT)),
                      sections["pipeline-segmentation"])
        self.assertIn("| sim_grasp | 67% | 100% | /ee_pose/z |", sections["pipeline-segmentation"])
        self.assertIn("\n".join(report_tables.learning_table(REPORT)),
                      sections["pipeline-learning"])
        self.assertIn("\n".join(report_tables.reproduction_table(REPORT, "reproduction")),
                      sections["pipeline-reproduction"])
        self.assertIn("| grasp | 1/2 | 0.99 | 25.6 mm | 0.2 mm | - |  |",
                      sections["pipeline-reproduction"])

    def test_a_report_with_problems_says_so(self):
        report = dict(REPORT, problems=["learn sim_push: 2 segment(s) learned, the task has 3"])
        run = results_doc.render("pipeline", report, MADE_BY)["pipeline-run"]
        self.assertIn("problems: learn sim_push: 2 segment(s) learned", run)

    def test_a_missing_marker_is_a_clear_error_and_nothing_is_written(self):
        text = doc_text(PIPELINE[:2] + PIPELINE[3:])  # no pipeline-learning
        self.write(text)
        with self.assertRaises(results_doc.SectionError) as err:
            results_doc.update("pipeline", REPORT, self.doc, made_by=MADE_BY)
        message = str(err.exception)
        self.assertIn(self.doc, message)
        self.assertIn("no generated section 'pipeline-learning'", message)
        self.assertIn("<!-- generated: pipeline-learning -->", message)
        self.assertIn("<!-- end generated -->", message)
        self.assertEqual(self.read(), text, "nothing written, not even the sections present")
        with self.assertRaises(results_doc.SectionError):
            results_doc.check("pipeline", self.doc)

    def test_an_unclosed_or_repeated_section_is_a_clear_error(self):
        unclosed = BEFORE + "<!-- generated: pipeline-run -->\nx\n\n" + doc_text(PIPELINE[1:])
        self.write(unclosed)
        with self.assertRaises(results_doc.SectionError) as err:
            results_doc.update("pipeline", REPORT, self.doc, made_by=MADE_BY)
        self.assertIn("'pipeline-run' (line 5) has no '<!-- end generated -->'", str(err.exception))
        self.assertEqual(self.read(), unclosed)
        repeated = doc_text(PIPELINE + ("pipeline-run",))
        with self.assertRaises(results_doc.SectionError) as err:
            results_doc.replace_sections(repeated, {"pipeline-run": "x"})
        self.assertIn("'pipeline-run' appears twice", str(err.exception))

    def test_other_sections_are_left_alone(self):
        text = doc_text(PIPELINE + ("bench-faults",))
        self.write(text)
        results_doc.update("pipeline", REPORT, self.doc, made_by=MADE_BY)
        self.assertIn(section("bench-faults"), self.read())

    def test_the_command_line_takes_kind_and_file(self):
        self.write(doc_text())
        path = os.path.join(self.tmp.name, "report.json")
        with open(path, "w") as f:
            json.dump(REPORT, f)
        self.assertEqual(results_doc.main(["pipeline=" + path, "--doc", self.doc]), 0)
        text = self.read()
        self.assertIn("*Generated from `./lfd pipeline`'s report.json, ", text)
        self.assertIn("| sim_grasp | 67% | 100% | /ee_pose/z |", text)
        with self.assertRaises(SystemExit):
            results_doc.main(["nonsense=" + path, "--doc", self.doc])
        self.write(BEFORE)
        self.assertEqual(results_doc.main(["pipeline=" + path, "--doc", self.doc]), 1)
        self.assertEqual(self.read(), BEFORE)


class Benchmarks(unittest.TestCase):
    """Each benchmark's result, as small as it gets, renders its section."""

    def render(self, kind, data):
        sections = results_doc.render(kind, data, MADE_BY)
        self.assertEqual(sorted(sections), sorted(results_doc.SOURCES[kind][1]))
        return "\n".join(sections.values())

    def test_signal_classes(self):
        at = {"demos": 8, "success_rate": 0.875, "covering": 0.9312, "f1": 0.95,
              "time_error_median_s": 0.02, "time_error_p95_s": None,
              "transitions_without_changepoint": 1}
        seeds = [{"seed": 0, "correct": {"0.5": 7, "1.0": 8}, "seconds": 1.25, "error": ""}]
        text = self.render("signal-classes", {"seeds": [0], "procedure": "", "config": "",
                                              "classes": {"strokes": {
                                                  "at": {"0.5": at, "1.0": at}, "seeds": seeds,
                                                  "changepoints_per_demo": 7.5,
                                                  "boundaries_per_demo": 8.0}}})
        self.assertIn("| strokes | 8 | 7 | 0.88 | 8 | 0.88 | 0.931 | 0.950 | 0.02 | - | 1 | "
                      "7.5/8.0 | 1.2 |", text)

    def test_faults(self):
        summary = {"nominal_runs": 2, "false_alarms": 1, "nominal_task_failures": 0,
                   "harmless_faults": 1, "harmless_faults_alarmed": 0, "faulty_runs": 4,
                   "detected": 3, "detection_rate": 0.75, "median_delay_s": 0.5, "roc_auc": 0.9,
                   "per_fault": {"grip_lost": {"runs": 4, "detected": 3,
                                               "median_delay_s": 0.5}},
                   "recovery": {"grasp_dropped": {"runs": 5, "task_succeeded": 4,
                                                  "recovered_runs": 5, "recoveries": 6,
                                                  "failed_tasks": ["drawer"]}}}
        text = self.render("faults", {"runs": [], "summary": summary, "complete": True})
        self.assertIn("| grasp_dropped | 5 | 4 | 5 | 6 | drawer |", text)
        self.assertIn("| grip_lost | 4 | 3 | 0.50 s |", text)
        self.assertIn("| **all** | **4** | **3 (75%)** | 0.50 s |", text)
        self.assertIn("ROC AUC of the anomaly score, faulty vs nominal: 0.90.", text)
        self.assertIn("before its summary", self.render("faults", {"runs": [{}]}))

    def test_pr2_signature(self):
        worst = {"channel": "gripper", "time": 3.0, "expected": 0.1, "measured": 0.5}
        rows = [{"train": ["pos_1", "pos_2"], "run": "neg_2", "segment": "pickup_leg",
                 "score": 5.1, "positive_max": 0.8, "worst": worst},
                {"train": ["pos_1", "pos_2"], "run": "pos_3", "alarms": [False, True],
                 "scores": [0.5, 1.2]}]
        text = self.render("pr2-signature", {"rows": rows, "separated": 1, "cases": 1})
        self.assertIn("| pos_1+pos_2 | neg_2 | pickup_leg | 5.10 | 0.80 | gripper t=3.0 s "
                      "expected 0.1 measured 0.5 |", text)
        self.assertIn("**1 of 1**. False alarms on the held-out successful runs: 1 of 2", text)

    def test_bench_pipeline(self):
        run = dict.fromkeys(results_doc.PIPELINE_FIGURES)
        run.update(datasets_s=100.0, demos=78, goals=50)
        text = self.render("bench-pipeline", {"runs": [run, run], "median": run,
                                              "pipeline_args": ["--goals", "3"]})
        self.assertIn("Pipeline options: --goals 3.", text)
        self.assertIn("| datasets_s | 100.0 | 100.0 | 100.0 |", text)
        self.assertIn("| demos | 78 | 78 | 78 |", text)
        self.assertIn("| learn_s | - | - | - |", text)

    def test_profiles(self):
        demo = {"dataset": "sim_wipe", "demos": 3, "sim_s": 49.9, "wall_s": 20.0,
                "demos_wall_s": 10.0, "demonstrator_parts_s": {"step_calls": 4.0, "settle": 1.0},
                "demonstrator_counts": {"step_calls": 469, "settle": 3},
                "bridge_parts_s": {"physics": 3.6, "publishing": 1.2}, "step_handshake_s": 2.9,
                "demonstrator_other_s": 0.5, "cpu_s": {"bridge_node": {"user": 5, "system": 2}}}
        text = self.render("profile-demo", demo)
        self.assertIn("3 demos of sim_wipe: 49.9 s of sim time in 20.0 s wall", text)
        self.assertIn("| bridge: physics | 3.60 | 36.0% |", text)
        self.assertIn("| 469 step round trips beyond the bridge's work | 2.90 | 29.0% |", text)
        self.assertIn("CPU by process (user + system): bridge_node 7.0 s.", text)
        goals = [{"wall_s": 10.0, "sim_s": 40.0, "parts": {"planning": 1.0, "motion": 8.0,
                                                           "motion_step_calls": 7.0},
                  "calls": {"planning": 1, "motion": 1}}]
        text = self.render("profile-reproduction", {"goals": goals, "cpu_s": {"x": [1.0, 0.5]}})
        self.assertIn("1 goals: 40.0 s of sim time in 10.0 s wall (4.0x real time).", text)
        self.assertIn("| motion (1) | 8.00 | 80.0% |", text)
        self.assertIn("| of motion: the rest (client loop, action traffic) | 1.00 | - |", text)


class CommittedDocument(unittest.TestCase):
    def test_docs_results_holds_every_generated_section(self):
        doc = results_doc.default_doc()
        self.assertTrue(os.path.exists(doc), doc)
        for kind in results_doc.SOURCES:
            results_doc.check(kind, doc)  # raises, naming the section, when one is missing


def all_tests():
    return unittest.TestSuite([unittest.defaultTestLoader.loadTestsFromTestCase(c)
                               for c in (Sections, Benchmarks, CommittedDocument)])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "results_doc_units", "__main__.all_tests")
