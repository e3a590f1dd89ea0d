"""Tests of the docs/results.md renderer on small hand-written step outputs.

  python3 -m unittest discover -s scripts/results   (ctest -R results_render_test)
"""
import json
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import config  # noqa: E402
import plan  # noqa: E402
import render  # noqa: E402
import values  # noqa: E402



def table(title, columns, *rows):
    return {"title": title, "columns": columns, "rows": [r.split() for r in rows]}


# What joint_bench --json writes (cells as printed).
JOINT_JSON = {"bench": "joint_bench", "tables": [
    table("Segmentation (GT person instances)",
          ["method", "mean instance IoU", "merged GT", "missed", "false pos."],
          "initial 0.669 0 0 0", "grabcut 0.869 0 1 0", "full 0.969 0 0 0"),
    table("Depth (GT person pixels)",
          ["method", "within 1%", "within 5%", "AbsRel", "completeness"],
          "wta 0.100 0.420 0.0500 1.000", "full 0.500 0.984 0.0100 1.000"),
    table("Flow (GT-valid person pixels)",
          ["method", "EPE px", "within 1 px", "within 3 px", "completeness"],
          "dis 0.309 0.9 0.99 1", "deepflow 0.321 0.9 0.99 1", "farneback 0.335 0.9 0.99 1",
          "full 0.217 0.9 0.99 1")]}
RUN_JSON = {"stages": [
    {"name": "poses", "seconds": 1.04, "peak_rss_mb": 100.4, "items": 3},
    {"name": "segments", "seconds": 10.25, "peak_rss_mb": 250.6, "items": 3},
    {"name": "consistency", "seconds": 0.5, "peak_rss_mb": 120.0, "items": 3}]}
EVAL_JSON = {
    "instances": {"mean_instance_iou": 0.96849}, "depth_people": {"delta_5pct": 0.9},
    "flow_people": {"epe_px": 0.2125}, "silhouette_overlap_error": {"value": 0.0415},
    "silhouette_overlap_error_baselines": {"deepflow": {"value": 0.05}, "dis": {"value": 0.0605},
                                           "farneback": {"value": None}},
    "projection_error": {"value": 0.1}, "meshes": {"chamfer_m": 0.00745},
    "vertex_drift": {"last_frame_drift_m": 0.0139, "last_frame_motion_m": 0.0161}}


class Fixture(unittest.TestCase):
    """A work folder of hand-written step outputs and a quick-mode context."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.work = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def put(self, name, content):
        with open(os.path.join(self.work, name), "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))

    def step(self, sid, out="", rc=0, err=""):
        self.put(sid + ".step.json", {
            "cmd": "build/bench/x --out %s/x.json" % self.work,
            "started": "2026-12-03 10:00:00 UTC",
            "load": "1.00 0.50 0.25", "wall": "12.3", "rss": "233", "rc": rc})
        self.put(sid + ".out", out)
        self.put(sid + ".err", err)

    def ctx(self, argv):
        c = config.config(argv, env={})
        return dict(c, work=self.work, commit="abc1234", commit_now="abc1234", t0=0, wall=5,
                    build_type="Release", today="2026-12-03", cores=2, cpu="Test CPU",
                    memory="8 GiB")

    def document(self, argv):
        return render.document(self.ctx(argv))


class ValuesTest(unittest.TestCase):
    def test_numbers_round_half_away_from_zero_and_print_shortest(self):
        self.assertEqual(values.r3(0.0005), "0.001")
        self.assertEqual(values.r3(0.9685), "0.969")
        self.assertEqual(values.r3(1.0), "1")
        self.assertEqual(values.r3(0.5), "0.5")
        self.assertEqual(values.r3(None), "")
        self.assertEqual(values.mm(0.00745), "7.5")
        self.assertEqual(values.num(None), "null")

    def test_md_cell_reads_the_table_whose_title_starts_with_heading(self):
        self.assertEqual(values.md_cell(JOINT_JSON, "Segmentation", "grabcut", 2), "0.869")
        self.assertEqual(values.md_cell(JOINT_JSON, "Segmentation", "grabcut", 4), "1")
        self.assertEqual(values.md_cell(JOINT_JSON, "Depth", "wta", 3), "0.420")
        self.assertEqual(values.md_cell(JOINT_JSON, "Flow", "full", 2), "0.217")
        self.assertEqual(values.md_cell(JOINT_JSON, "Flow", "nope", 2), "")
        self.assertEqual(values.md_cell(JOINT_JSON, "Flow", "full", 9), "")
        self.assertEqual(values.md_cell(None, "Flow", "full", 2), "")

    def test_md_table_prints_the_table_as_the_bench_did(self):
        self.assertEqual(values.md_table(JOINT_JSON, "Depth"), [
            "| method | within 1% | within 5% | AbsRel | completeness |", "|---|---|---|---|---|",
            "| wta | 0.100 | 0.420 | 0.0500 | 1.000 |",
            "| full | 0.500 | 0.984 | 0.0100 | 1.000 |"])
        self.assertEqual(values.md_table(JOINT_JSON, "Time per view"), [])
        self.assertEqual(values.md_table(None, "Depth"), [])

    def test_google_benchmark_times_in_ms(self):
        g = {"benchmarks": [{"name": "BM_MaxFlow/0/4", "real_time": 21345.0, "time_unit": "us"},
                            {"name": "BM_MaxFlow/1/4", "real_time": 9.4e7, "time_unit": "ns"}]}
        self.assertEqual(values.gb_ms(g, "BM_MaxFlow/0/4"), "21.3")
        self.assertEqual(values.gb_ms(g, "BM_MaxFlow/1/4"), "94.0")
        self.assertEqual(values.gb_ms(None, "BM_MaxFlow/1/4"), "")
        self.assertEqual(values.ratio("94.0", "21.3"), "4.4")
        self.assertEqual(values.ratio("", "21.3"), "")

    def test_counters_from_the_tables_and_google_benchmark_json(self):
        shelf = {"tables": [
            table("PCP (%), raw triangulation", ["limb", "actor1", "avg(1-3)"], "all 90.0 90.0"),
            table("PCP (%), tracked + smoothed", ["limb", "actor1", "avg(1-3)"],
                  "head 95.0 95.0", "all 97.0 96.0")]}
        self.assertEqual(values.shelf_pcp(shelf), "96.0")
        self.assertEqual(values.shelf_pcp(None), "")
        columns = ["world", "views x size", "person", "s", "points", "vertices", "chamfer mm"]
        fusion = {"tables": [table("FuseObject from GT depth", columns,
                                   "handshake 8x480x270 1 5.7 26952 43095 7.4",
                                   "handshake 8x960x540 1 6.1 108174 43431 9",
                                   "handshake 8x480x270 2 5.3 32133 40595 8.1")]}
        self.assertEqual(values.fusion_chamfer(fusion), "7.4/8.1")
        self.assertEqual(values.fusion_chamfer(None), "")
        tracks = {"benchmarks": [{"name": "BM_TemporalTracks/12/8", "precision": 0.98151}]}
        self.assertEqual(values.gb_counter(tracks, "precision"), "0.982")
        self.assertEqual(values.gb_counter(tracks, "recall"), "")
        self.assertEqual(values.synth_fps("wrote 6 frames (12.5 frames/s; 3 s)\n"), "12.5")


class ProvenanceTest(Fixture):
    def test_provenance_names_command_run_and_hides_the_work_folder(self):
        self.step("joint", "joint_bench: 4 views\n")
        p = render.Work(self.work).provenance("joint")
        self.assertEqual(p, "\nCommand: `build/bench/x --out <tmp>/x.json`  \n"
                            "Run: 2026-12-03 10:00:00 UTC, wall 12.3 s, peak RSS 233 MB, "
                            "load average at start 1.00 0.50 0.25.\n\n")

    def test_a_failed_step_is_marked_with_the_end_of_its_stderr(self):
        err = "".join("line %d\n" % i for i in range(30))
        self.step("sparse", "partial\n", rc=3, err=err)
        doc = self.document(["--quick", "--only", "sparse"])
        self.assertIn("**FAILED (exit status 3).** Last lines of stderr:\n\n```text\nline 10\n",
                      doc)
        self.assertIn("line 29\n```\n", doc)
        self.assertNotIn("line 9\n", doc)
        self.assertIn("## Sparse multi-view points\n", doc)
        self.assertIn("```text\npartial\n```\n", doc)


class DocumentTest(Fixture):
    def test_header_names_mode_machine_and_commit(self):
        doc = self.document(["--quick", "--only", "seg"])
        self.assertTrue(doc.startswith("# Results\n\nGenerated by `scripts/results.sh --quick`;"))
        self.assertIn("**This is a `--quick` run** (2026-12-03)", doc)
        self.assertIn("`u4d run` on 4 views 320x180 x 3 frames;", doc)
        self.assertIn("Machine: 2 cores, Test CPU,\n8 GiB memory; build `build` (Release);\n"
                      "commit abc1234;\nstarted 1970-01-01 00:00:00 UTC, whole script 5 s.\n", doc)
        self.assertTrue(doc.endswith("- The optional GPL comparison `mrf_libmaxflow_bench` "
                                     "(off by default).\n"))
        full = self.document(["--only", "seg"])
        self.assertNotIn("--quick", full.split("\n")[2])
        self.assertNotIn("This is a `--quick` run", full)

    def test_joint_tables_and_summary_cells(self):
        self.step("joint", "joint_bench: 4 views\n")
        self.put("joint.json", JOINT_JSON)
        doc = self.document(["--quick", "--only", "seg,depth,flow"])
        self.assertIn("| segmentation: mean instance IoU (Segmentation comparison) | "
                      "initial 0.669, "
                      "GrabCut 0.869 | full 0.969 | Segmentation |\n", doc)
        self.assertIn("| flow EPE on people, px (motion evaluation) | DIS 0.309, DeepFlow 0.321, "
                      "Farneback 0.335 | full 0.217 | Flow |\n", doc)
        seg = doc.split("## Segmentation")[1].split("\n## ")[0]
        self.assertIn("P_PS (rows of the paper's table).\n\n| method | mean instance IoU |", seg)
        self.assertIn("| method | mean instance IoU | merged GT | missed | false pos. |\n"
                      "|---|---|---|---|---|\n| initial | 0.669 | 0 | 0 | 0 |\n", seg)
        self.assertIn("| full | 0.969 | 0 | 0 | 0 |\n\nCommand: `", seg)
        self.assertIn("## Reconstruction / depth (paper Table \"Reconstruction evaluation\")", doc)
        self.assertIn("### Time per view and energy trace (same joint_bench run)\n\n\n\n", doc)
        self.assertNotIn("## Graph cuts", doc)

    def test_a_bench_without_its_json_has_empty_tables_and_cells(self):
        self.step("joint", "an old run's stdout\n| full | 0.969 | 0 | 0 | 0 |\n")
        doc = self.document(["--quick", "--only", "seg"])
        self.assertIn("initial , GrabCut  | full  | Segmentation |", doc)
        self.assertNotIn("| full | 0.969", doc)
        self.assertIn("(no joint.json: this step ran before the benches wrote their tables as "
                      "JSON)\n\nCommand: `", doc)

    def test_real_data_summary_rows_from_their_json(self):
        self.step("middlebury")
        self.put("middlebury.json", {"tables": [
            table("Per scene", ["scene", "method"], "tsukuba sgbm"),
            table("Mean over the scenes", ["method", "mean bad > 1 px"], "ours-wta 0.2",
                  "ours-mrf 0.1", "sgbm 0.3", "bm 0.4")]})
        self.step("sintel")
        self.put("sintel.json", {"tables": [table(
            "All cases (pixel-weighted)", ["method", "EPE all", "EPE noc"], "deepflow 1.5 1.0",
            "dis 2.5 2.0", "ours-fusion 3.5 3.0", "ours-fusion-df 1.4 0.9")]})
        doc = self.document(["--quick", "--only", "middlebury,sintel"])
        self.assertIn("| SGBM 0.3, BM 0.4 | E_d WTA 0.2, E_d + E_s 0.1 | Middlebury |\n", doc)
        self.assertIn("| DeepFlow 1.5 / 1.0, DIS 2.5 / 2.0 | from zero 3.5 / 3.0, "
                      "from DeepFlow 1.4 / 0.9 | Sintel |\n", doc)

    def test_end_to_end_tables_from_scene_json(self):
        self.step("speed_4v_320x180_synth")
        self.step("speed_4v_320x180", "evaluated in %s/scene\n" % self.work)
        self.put("speed_4v_320x180.run.json", RUN_JSON)
        self.put("speed_4v_320x180.eval.json", EVAL_JSON)
        doc = self.document(["--quick", "--only", "speed"])
        self.assertIn("| 4v_320x180 | segments | 10.3 | 251 | 3 |\n", doc)
        self.assertIn("| 4v_320x180 | **total** | 11.8 | 251 | |\n", doc)
        self.assertIn("| 4v_320x180 | 0.968 | 0.9 | 0.213 | 0.042 | 0.1 | 7.5 | 13.9 (16.1) |\n",
                      doc)
        self.assertIn("| 4v_320x180 | (no consistency.json) | | | | | | |\n", doc)
        self.assertIn("| `u4d run` 4v_320x180 x 3 frames: IoU, S_e, total s, peak MB | | "
                      "0.968, 0.042, 12 s, 251 MB | Speed |\n", doc)
        self.assertIn("```text\nevaluated in <tmp>/scene\n```\n", doc)

    def test_scenario_rows_and_a_failed_run(self):
        self.put("scen_walk.eval.json", EVAL_JSON)
        self.put("scen_walk.run.json", RUN_JSON)
        self.put("scen_walk.initial.json", {"instances": {
            "mean_instance_iou": 0.6, "merge_rate_where_touching": 0.5,
            "merged_touching_images": 2, "touching_images": 4}, "identity": {}})
        doc = self.document(["--quick", "--only", "scenarios"])
        self.assertIn("| walk | 0.6 | 0.968 | 0.9 | 0.213 | 0.042 | 0.05 | 0.061 |  | 0.1 | 7.5 | "
                      "13.9 (16.1) | 3.9 |\n", doc)
        self.assertIn("| handshake | (no eval.json: the run failed) | | | | | | | | | | | |\n", doc)
        self.assertIn("| walk |  |  | null / null | null / null | 0.5 (2 of 4) |\n", doc)
        self.assertIn("| realistic-moving | (no eval.json: the run failed)"
                      " | | | | | | | | | | | |\n"
                      "\nIdentity (docs/metrics.md", doc)
        self.assertIn("| S_e of the GT masks carried by the flow, two people walking (Silhouette "
                      "overlap error) | DeepFlow 0.05, DIS 0.061, Farneback  | ours 0.042 |", doc)

    def test_true_mask_rows_and_a_failed_run(self):
        self.put("tm_realistic_default.eval.json", EVAL_JSON)
        self.put("tm_realistic_default.run.json", RUN_JSON)
        doc = self.document(["--quick", "--only", "true_masks"])
        self.assertIn("## True masks given", doc)
        self.assertIn("| realistic | default | 0.968 |  | 7.5 | 3.9 |\n", doc)
        self.assertIn("| realistic | trusted | (no eval.json: the run failed) | | | |\n", doc)
        self.assertIn("| handshake | default | (no eval.json: the run failed) | | | |\n", doc)

    def test_graph_cuts_and_tracks_summary_from_google_benchmark_json(self):
        self.step("tracks", "precision=0.9 on the console\n")
        self.put("tracks.gbench.json", {"benchmarks": [{"name": "BM_TemporalTracks/12/8",
                                                         "precision": 0.98151}]})
        self.step("mrf", "console table\n")
        self.put("mrf.gbench.json", {"benchmarks": [
            {"name": "BM_MaxFlow/0/4", "real_time": 21.3, "time_unit": "ms"},
            {"name": "BM_MaxFlow/1/4", "real_time": 94.1, "time_unit": "ms"}]})
        doc = self.document(["--quick", "--only", "mrf,tracks"])
        self.assertIn("| temporal tracks: share of steps within 2 px of GT flow | | 0.982 | "
                      "Temporal tracks |\n", doc)
        self.assertIn("```text\nprecision=0.9 on the console\n```\n", doc)
        self.assertIn("| max-flow 480x270 4-connected, ms | Boost BK 94.1 | own BK 21.3 (4.4x) | "
                      "Graph cuts |\n", doc)
        self.assertIn("| alpha-expansion 480x270, 32 labels, ms | Boost BK  | own BK  (x) |", doc)


class UpdateTest(Fixture):
    OLD = ("# Results\n\nheader\n\n## Summary\n\n| old summary |\n\n"
           "## Segmentation (x)\n\nold seg\n\n"
           "## Flow (y)\n\nold flow\n\n## Not yet measured\n\n- nothing\n")
    NEW = ("# Results\n\nnew header\n\n## Summary\n\n| new summary |\n\n## Flow (y)\n\nnew flow\n\n"
           "## Sintel (z)\n\nnew sintel\n\n## Not yet measured\n\n- new list\n")

    def test_splice_replaces_sections_by_heading_and_adds_new_ones(self):
        doc = render.splice(self.OLD, self.NEW, "NOTE")
        self.assertEqual(doc, "# Results\n\nheader\n\nNOTE\n\n## Summary\n\n"
                              "| old summary |\n| new summary |\n\n"
                              "## Segmentation (x)\n\nold seg\n\n## Flow (y)\n\nnew flow\n\n"
                              "## Sintel (z)\n\nnew sintel\n\n\n## Not yet measured\n\n- nothing\n")

    def test_splice_takes_the_summary_rows_of_the_sections_run(self):
        head = "| result (paper table) | baseline(s) | ours | section |\n|---|---|---|---|\n"
        old = ("# Results\n\n## Summary\n\n" + head + "| seg IoU | a | 0.9 | Segmentation |\n"
               "| speed, s | | 10.9 s | Scaling |\n\n## Scaling (s)\n\nold\n\n"
               "## Not yet measured\n\n- x\n")
        new = ("# Results\n\n## Summary\n\n" + head + "| speed, s | | 12.1 s | Scaling |\n"
               "| new result | | 1 | Scaling |\n\n## Scaling (s)\n\nnew\n\n"
               "## Not yet measured\n\n- y\n")
        doc = render.splice(old, new, "NOTE")
        self.assertEqual(doc, "# Results\n\nNOTE\n\n## Summary\n\n" + head +
                         "| seg IoU | a | 0.9 | Segmentation |\n| speed, s | | 12.1 s | Scaling |\n"
                         "| new result | | 1 | Scaling |\n\n## Scaling (s)\n\nnew\n\n"
                         "## Not yet measured\n\n- x\n")

    def test_write_updates_only_with_only(self):
        out = os.path.join(self.work, "results.md")
        self.put("results.md", self.OLD)
        render.write(self.ctx(["--only", "flow", "--update"]), out, self.NEW)
        with open(out) as f:
            doc = f.read()
        self.assertIn("Regenerated later, at commit abc1234 on 2026-12-03 by `scripts/results.sh "
                      "--only flow --update`", doc)
        self.assertIn("old seg", doc)
        self.assertIn("new flow", doc)
        render.write(self.ctx(["--update"]), out, self.NEW)
        with open(out) as f:
            self.assertEqual(f.read(), self.NEW)


class PlanTest(unittest.TestCase):
    def steps(self, argv):
        return [a for a in plan.plan(config.config(argv, env={}), "/w") if a[0] == "run"]

    def test_options_choose_the_steps_and_sizes(self):
        ids = [a[1] for a in self.steps(["--quick", "--only", "seg,mrf"])]
        self.assertEqual(ids, ["joint", "mrf"])
        joint = self.steps(["--quick", "--only", "seg"])[0][2]
        self.assertEqual(joint[0], "build/bench/joint_bench")
        self.assertEqual(joint[-2:], ["--json", "/w/joint.json"])
        mrf = self.steps(["--quick", "--only", "mrf"])[0][2]
        self.assertEqual(mrf, ["build/bench/mrf_bench", "--benchmark_min_time=0.01",
                               "--benchmark_out=/w/mrf.gbench.json", "--benchmark_out_format=json"])
        speed = [a[1] for a in self.steps(["--only", "speed", "--speed-views", "4 8"])]
        self.assertEqual(speed, ["speed_4v_480x270_synth", "speed_4v_480x270",
                                 "speed_4v_480x270_consistency", "speed_8v_480x270_synth",
                                 "speed_8v_480x270", "speed_8v_480x270_consistency"])
        true_masks = self.steps(["--only", "true_masks"])
        self.assertEqual([a[1] for a in true_masks],
                         ["tm_realistic_synth", "tm_realistic_default", "tm_realistic_trusted",
                          "tm_handshake_synth", "tm_handshake_default", "tm_handshake_trusted"])
        synth = true_masks[0][2]
        self.assertEqual(synth[1:5], ["synth", "--preset", "realistic", "--seed"])
        self.assertEqual(synth[-4:], ["--degrade", "none", "-o", "/w/tm_realistic"])
        self.assertEqual(true_masks[2][2][-1], "joint.labels.appearance_inset_px=0")
        abl = self.steps(["--only", "ablations"])
        self.assertEqual([a[1] for a in abl],
                         ["abl_synth"] + ["abl_" + a for a in config.ABLATIONS])
        self.assertEqual(abl[0][2][-6:], ["--width", "480", "--height", "270", "-o", "/w/abl_walk"])
        # Each energy runs on the whole of its short capture: a run of part of
        # a capture writes no eval.json, and the table would have no rows.
        self.assertTrue(all("--frames" not in a[2] for a in abl[1:]))

    def test_every_prose_block_exists(self):
        prose = render.load_prose()
        for name in ["header", "quick", "machine", "summary", "seg", "not_measured", "speed_eval"]:
            self.assertIn(name, prose)
        self.assertTrue(prose["seg"].startswith('## Segmentation (paper Table "Segmentation'))


if __name__ == "__main__":
    unittest.main()
