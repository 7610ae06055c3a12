#!/usr/bin/env python3
"""`orthoflow segment --labels-out` and `orthoflow evaluate-segmentation`, through the CLI.

- segment --labels-out writes the organized frame with a label field (0 none, 1 table, k >= 2
  object k - 2 of the objects it printed): as many object labels as objects, each with the point
  count the JSON reports;
- evaluate-segmentation over a folder of three learn-split frames: JSON and Markdown agree, the
  per-category table appears with --names, a PNG per frame with --png, and --out writes both files;
- an unreadable frame in the folder is a failed row and exit code 2, the others still scored;
- an unorganized frame asked for --labels-out is refused (exit 2), nothing written;
- run --source pcd:DIR --labels-out OUT writes one labels file per frame, label for label what
  segment --labels-out writes for that file with the same graph (one chain).

Usage: check_segmentation_eval.py ORTHOFLOW SHARED_DIR WORK_DIR
"""
import collections
import json
import os
import shutil
import struct
import sys

from cli_check import expect, run


def labels_of(cli, path, work):
    """The label field and height of a binary_compressed PCD, read without orthoflow: the header,
    then the LZF block (decoded here), field by field."""
    data = open(path, "rb").read()
    header_end = data.index(b"DATA binary_compressed\n") + len(b"DATA binary_compressed\n")
    header = data[:header_end].decode()
    fields = dict(line.split(" ", 1) for line in header.splitlines() if " " in line)
    names = fields["FIELDS"].split()
    sizes = [int(s) for s in fields["SIZE"].split()]
    n = int(fields["POINTS"])
    comp, raw = struct.unpack("<II", data[header_end:header_end + 8])
    src = data[header_end + 8:header_end + 8 + comp]
    out = bytearray()
    i = 0
    while i < len(src):
        ctrl = src[i]
        i += 1
        if ctrl < 32:
            out += src[i:i + ctrl + 1]
            i += ctrl + 1
        else:
            length = ctrl >> 5
            ref = len(out) - ((ctrl & 0x1f) << 8) - 1
            if length == 7:
                length += src[i]
                i += 1
            ref -= src[i]
            i += 1
            for _ in range(length + 2):
                out.append(out[ref])
                ref += 1
    expect(len(out) == raw, f"{path}: LZF gave {len(out)} bytes, header says {raw}")
    offset = sum(s * n for name, s in zip(names, sizes) if names.index(name) < names.index("label"))
    return struct.unpack(f"<{n}I", bytes(out[offset:offset + 4 * n])), int(fields["HEIGHT"])


def main():
    cli, shared, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    frame = os.path.join(shared, "data", "mosd_learn", "learn13.pcd")
    out = os.path.join(work, "labels.pcd")
    seg = json.loads(run(cli, "segment", frame, "--graph", "tabletop", "--labels-out", out,
                         "--json").stdout)
    labels, height = labels_of(cli, out, work)
    expect(height == 480, "the labels file stays organized")
    counts = collections.Counter(labels)
    objects = sorted(k for k in counts if k >= 2)
    expect(objects == list(range(2, 2 + len(seg["objects"]))),
           f"object labels {objects} for {len(seg['objects'])} objects")
    # Points are those clustered: every pixel, or at the budget's stride s every s-th pixel of every
    # s-th row, the pixels between them labelled from their cell's corners (about s^2 as many).
    stride = seg["budget"]["stride"]
    for k in objects:
        points = seg["objects"][k - 2]["points"]
        if stride == 1:
            expect(counts[k] == points, f"object {k - 2}: {counts[k]} labelled points, JSON says {points}")
        else:
            expect(0.75 * points * stride * stride <= counts[k] <= 1.25 * points * stride * stride,
                   f"object {k - 2} at stride {stride}: {counts[k]} labelled pixels for {points} points")
    expect(counts[1] > 100000, f"table points {counts[1]}")

    dataset = os.path.join(work, "frames")
    os.makedirs(dataset)
    dataset_frames = os.path.join(work, "run_frames")  # the same frames, without the broken one
    os.makedirs(dataset_frames)
    for name in ("learn0", "learn17", "learn33"):
        shutil.copy(os.path.join(shared, "data", "mosd_learn", name + ".pcd"), dataset)
        shutil.copy(os.path.join(shared, "data", "mosd_learn", name + ".pcd"), dataset_frames)
    names = os.path.join(work, "names.txt")
    with open(names, "w") as f:
        f.write("learn0 boxes\nlearn17 stacked\nlearn33 cylindric\n")
    report_dir = os.path.join(work, "report")
    p = run(cli, "evaluate-segmentation", "--dataset", dataset, "--names", names, "--png",
            os.path.join(work, "png"), "--out", report_dir, "--json", "--quiet")
    report = json.loads(p.stdout)[0]
    expect(report["segmenter"] == "orthoflow", "segmenter name")
    expect([f["frame"] for f in report["frames"]] == ["learn0", "learn17", "learn33"], "frame order")
    total = report["total"]
    expect(total["frames"] == 3 and total["failed"] == 0, f"totals {total}")
    expect(total["objects"]["truth"] == 2 + 2 + 5, f"ground-truth objects {total['objects']}")
    expect(set(report["categories"]) == {"boxes", "stacked", "cylindric"}, "categories")
    for f in report["frames"]:
        expect(f["plane"]["correct"], f"{f['frame']}: plane {f['plane']}")
        expect(os.path.getsize(os.path.join(work, "png", f["frame"] + ".png")) > 1000, "png")
    md = open(os.path.join(report_dir, "segmentation.md")).read()
    expect("## Per category" in md and "| learn17 | stacked | orthoflow |" in md, "markdown rows")
    expect(json.load(open(os.path.join(report_dir, "segmentation.json")))[0]["total"] == total,
           "the JSON file is the printed report")

    with open(os.path.join(dataset, "broken.pcd"), "w") as f:
        f.write("VERSION .7\nFIELDS x y z\n")
    p = run(cli, "evaluate-segmentation", "--dataset", dataset, "--json", "--quiet", code=2)
    report = json.loads(p.stdout)[0]
    expect(report["total"]["failed"] == 1 and report["total"]["frames"] == 4, "one failed row")
    expect("error" in report["frames"][0] and report["frames"][0]["frame"] == "broken", "its row")
    expect("1 of 4 frames were not scored" in p.stderr, p.stderr)
    p = run(cli, "evaluate-segmentation", "--dataset", os.path.join(work, "nothing"), code=2)
    expect("is not a directory" in p.stderr, p.stderr)

    flat = os.path.join(work, "flat.pcd")
    with open(flat, "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 400\n"
                "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 400\nDATA ascii\n")
        for i in range(400):
            f.write(f"{(i % 20) * 0.01 - 0.1} {(i // 20) * 0.01 - 0.1} 1\n")
    p = run(cli, "segment", flat, "--labels-out", os.path.join(work, "flat_labels.pcd"), code=2)
    expect("organized" in p.stderr, p.stderr)
    expect(not os.path.exists(os.path.join(work, "flat_labels.pcd")), "nothing written")
    run_out = os.path.join(work, "run_labels")
    p = run(cli, "run", "--source", "pcd:" + dataset_frames, "--labels-out", run_out, "--rate", "max")
    expect("labels: 3 frame(s) written" in p.stdout, p.stdout)
    for k, name in enumerate(("learn0", "learn17", "learn33")):
        single = os.path.join(work, name + "_labels.pcd")
        run(cli, "segment", os.path.join(dataset_frames, name + ".pcd"), "--graph", "tabletop",
            "--labels-out", single)
        ours, _ = labels_of(cli, single, work)
        theirs, h = labels_of(cli, os.path.join(run_out, "frame_%06d.pcd" % k), work)
        expect(h == 480, "run's labels file stays organized")
        expect(ours == theirs, f"{name}: run and segment label the frame differently")
    print("ok")


if __name__ == "__main__":
    main()
