#!/usr/bin/env python3
"""Enforces the dependency arrows between the product folders (STYLE rule 1) on #include lines.

Every `#include "folder/..."` (or `<folder/...>`) in a product folder must name the folder itself or
a folder it may use (ALLOWED below, the one place the table lives). Also: only drivers/ includes
libusb.h, and kernels/ includes no TBB, iceoryx, LevelDB or libusb header. Prints the table it
enforces, then one line per violation, `file:line: ...`; exits 1 if there is any.

usage: check_include_arrows.py [--root DIR]   (default: the checkout holding this script)
       check_include_arrows.py --self-test    (the checker against a scratch tree with known faults)
"""
import argparse
import os
import re
import sys
import tempfile

# folder -> folders it may include besides itself. apps is the CLI on top: it may use everything.
ALLOWED = {
    "core": [],
    "memory_pool": ["core"],
    "kernels": ["core", "memory_pool"],
    "engine": ["core", "memory_pool", "kernels"],
    "formats": ["core", "memory_pool", "kernels"],
    "simulation": ["core", "memory_pool", "kernels", "formats", "drivers"],
    "drivers": ["core", "memory_pool", "kernels"],
    "learning": ["core", "memory_pool", "kernels"],
    "manipulation": ["core", "memory_pool", "kernels", "drivers"],
    "evaluation": ["core", "memory_pool", "kernels", "formats", "simulation", "learning"],
    "graphs": ["core", "memory_pool", "kernels", "engine", "formats", "simulation", "drivers", "learning",
               "manipulation"],
    "ui": ["core", "memory_pool", "kernels", "engine", "formats", "simulation", "drivers", "learning",
           "manipulation", "graphs"],
    "bridge": ["core", "memory_pool", "kernels", "engine", "formats", "simulation", "drivers", "learning",
               "manipulation", "graphs"],
    "deploy": ["core"],
    "apps": ["core", "memory_pool", "kernels", "engine", "formats", "simulation", "drivers", "learning", "bridge",
             "evaluation", "graphs", "ui", "manipulation", "deploy"],
}
# Rooms inside a folder, and the rooms of the same folder each may include besides itself ("." is a
# file directly in the folder). A folder's own files follow these arrows; other folders are not bound
# by them. Each device driver uses the USB seam and never the other device; the simulated devices
# look at the simulated world, never the other way; in graphs/, a frame is the bottom, channels
# carry frames' commands, services serve the nodes, and sessions run whole graphs.
ROOMS = {
    "drivers": {"usb": [], "kinect": ["usb"], "jaco": ["usb"]},
    "simulation": {"world": [], "devices": ["world"]},
    "graphs": {"frame": [], "channels": ["frame"], "services": ["frame", "channels"],
               "nodes": ["frame", "channels", "services"], ".": ["frame", "channels", "services", "nodes"],
               "sessions": ["frame", "channels", "services", "nodes", "."]},
}
# Top-level folders beside the product that product code never includes (STYLE rule 1).
NOT_PRODUCT = ["tests", "bench", "toolchains", "docs", "scripts", "config"]
# Headers only drivers/ may include (its libusb transport, STYLE rule 16).
DRIVERS_ONLY = re.compile(r"(^|/)(libusb\.h|libusb_api\.hpp)$")
# Headers kernels/ never includes (STYLE rule 1: xsimd and Eigen only).
KERNELS_FORBIDDEN = re.compile(r"^(tbb/|oneapi/|iceoryx|iox/|leveldb/|libusb)|(^|/)libusb\.h$")
# Folders scanned for libusb.h besides the product ones.
ALSO_SCANNED = ["tests", "bench"]
# The one exception to "libusb.h in drivers/ only": the test-only libusb-1.0 shim over the simulated
# Kinect (tests/support/sim_libusb/README.md) implements libusb's API, so it needs libusb's own header
# for the ABI. Nothing in it is linked into the product.
LIBUSB_SHIM_DIR = "tests/support/sim_libusb/"

SOURCE_SUFFIXES = (".hpp", ".h", ".hh", ".cpp", ".cc", ".cxx", ".inl", ".ipp", ".hpp.in", ".cpp.in", ".h.in")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def print_table(out):
    out.write("include arrows enforced (a folder may always include itself):\n")
    for folder, uses in ALLOWED.items():
        out.write("  %-12s may use: %s\n" % (folder, ", ".join(uses) if uses else "(nothing of ours)"))
    for folder, rooms in ROOMS.items():
        for room, uses in rooms.items():
            out.write("  %-12s may use: %s\n" % ("%s/%s" % (folder, room),
                      ", ".join("%s/%s" % (folder, r) for r in uses) if uses else "(no other room)"))
    out.write("  never from product code: %s/\n" % "/, ".join(NOT_PRODUCT))
    out.write("  libusb.h: drivers/ only (and the test shim %s); kernels/: no tbb, oneapi/tbb, iceoryx, iox, leveldb or "
              "libusb headers\n" % LIBUSB_SHIM_DIR)


def includes_of(path):
    """(line number, header) for each #include outside /* */ comments."""
    found = []
    in_comment = False
    with open(path, encoding="utf-8", errors="replace") as text:
        for number, line in enumerate(text, start=1):
            if in_comment:
                if "*/" not in line:
                    continue
                line = line.split("*/", 1)[1]
                in_comment = False
            match = INCLUDE.match(line)
            if match:
                found.append((number, match.group(2).strip()))
            elif "/*" in line and "*/" not in line.split("/*", 1)[1]:
                in_comment = True
    return found


def source_files(root, folder):
    base = os.path.join(root, folder)
    for directory, subdirs, files in os.walk(base):
        subdirs[:] = sorted(d for d in subdirs if not d.startswith("."))
        for name in sorted(files):
            if name.endswith(SOURCE_SUFFIXES):
                yield os.path.join(directory, name)


def room_of(folder, parts):
    """The room of a path inside @p folder given as its components after the folder, or None."""
    rooms = ROOMS.get(folder)
    if rooms is None:
        return None
    if len(parts) >= 2 and parts[0] in rooms:
        return parts[0]
    return "." if len(parts) == 1 else None


def room_violation(folder, rel, header):
    """A sentence when @p header breaks the room arrows of @p folder for the file @p rel, else None."""
    parts = rel.replace(os.sep, "/").split("/")
    own = room_of(folder, parts[1:])
    head = header.split("/")
    if own is None or head[0] != folder:
        return None
    target = room_of(folder, head[1:])
    if target is None or target == own or target in ROOMS[folder][own]:
        return None
    uses = ", ".join("%s/%s" % (folder, r) for r in ROOMS[folder][own]) or "no other room"
    return "%s/%s may not include \"%s\" (%s/%s may use: %s)" % (folder, own, header, folder, own, uses)


def violations_in(root, folder, path):
    rel = os.path.relpath(path, root)
    problems = []
    for number, header in includes_of(path):
        where = "%s:%d" % (rel, number)
        first = header.split("/", 1)[0] if "/" in header else None
        if folder in ALLOWED:
            if first in ALLOWED and first != folder and first not in ALLOWED[folder]:
                uses = ", ".join(ALLOWED[folder]) or "nothing of ours"
                problems.append("%s: %s/ may not include \"%s\" (%s/ may use: %s)" % (where, folder, header, folder,
                                                                                     uses))
            elif room_violation(folder, rel, header):
                problems.append("%s: %s" % (where, room_violation(folder, rel, header)))
            elif first in NOT_PRODUCT:
                problems.append("%s: %s/ may not include \"%s\" (product code never includes %s/)" % (
                    where, folder, header, first))
        shim = rel.replace(os.sep, "/").startswith(LIBUSB_SHIM_DIR)
        if folder != "drivers" and not shim and DRIVERS_ONLY.search(header):
            problems.append("%s: \"%s\" outside drivers/ (only the libusb transport includes libusb.h)" % (
                where, header))
        elif folder == "kernels" and KERNELS_FORBIDDEN.search(header):
            problems.append("%s: kernels/ may not include \"%s\" (kernels use xsimd and Eigen only)" % (
                where, header))
    return problems


def check(root, out):
    print_table(out)
    problems = []
    scanned = 0
    for folder in list(ALLOWED) + ALSO_SCANNED:
        if not os.path.isdir(os.path.join(root, folder)):
            continue
        for path in source_files(root, folder):
            scanned += 1
            problems.extend(violations_in(root, folder, path))
    for line in problems:
        out.write(line + "\n")
    out.write("%d files scanned, %d violation%s\n" % (scanned, len(problems), "" if len(problems) == 1 else "s"))
    return problems


def self_test():
    """The checker on a scratch tree: every kind of fault is found, named by file and line, and
    allowed includes (own folder, allowed folders, system headers, comments) pass."""
    files = {
        "core/a.hpp": '#include <vector>\n#include "core/b.hpp"\n',
        "kernels/k.hpp": '#include "core/result.hpp"\n#include "memory_pool/p.hpp"\n#include "engine/graph.hpp"\n'
                         '#include <tbb/parallel_for.h>\n#include "iceoryx_posh/x.hpp"\n#include <leveldb/db.h>\n',
        "kernels/detail/k.inl": '/* #include "learning/x.hpp"\n*/\n// #include "graphs/x.hpp"\n#include <xsimd/xsimd.hpp>\n',
        "learning/l.cpp": '#include "kernels/k.hpp"\n  #  include "formats/pcd_reader.hpp"\n',
        "formats/f.cpp": '#include "tests/support/counting_new.hpp"\n#include <libusb-1.0/libusb.h>\n',
        "drivers/d.cpp": '#include <libusb.h>\n#include "memory_pool/p.hpp"\n#include "graphs/g.hpp"\n',
        "apps/main.cpp": '#include "graphs/tabletop.hpp"\n#include "evaluation/e.hpp"\n',
        "tests/t.cpp": '#include "graphs/tabletop.hpp"\n#include <libusb.h>\n',
        "tests/support/sim_libusb/shim.cpp": '#include <libusb-1.0/libusb.h>\n',
        "tests/support/sim_libusb_other/x.cpp": '#include <libusb-1.0/libusb.h>\n',
        "drivers/kinect/k.cpp": '#include "drivers/usb/u.hpp"\n#include "drivers/jaco/j.hpp"\n#include "drivers/kinect/x.hpp"\n',
        "simulation/world/w.cpp": '#include "simulation/devices/d.hpp"\n#include "drivers/kinect/x.hpp"\n',
        "graphs/nodes/n.cpp": '#include "graphs/services/s.hpp"\n#include "graphs/sessions/t.hpp"\n#include "graphs/tabletop.hpp"\n',
        "graphs/tabletop.cpp": '#include "graphs/nodes/n.hpp"\n',
    }
    expected = [
        "kernels/k.hpp:3: kernels/ may not include \"engine/graph.hpp\"",
        "kernels/k.hpp:4: kernels/ may not include \"tbb/parallel_for.h\"",
        "kernels/k.hpp:5: kernels/ may not include \"iceoryx_posh/x.hpp\"",
        "kernels/k.hpp:6: kernels/ may not include \"leveldb/db.h\"",
        "learning/l.cpp:2: learning/ may not include \"formats/pcd_reader.hpp\"",
        "formats/f.cpp:1: formats/ may not include \"tests/support/counting_new.hpp\"",
        "formats/f.cpp:2: \"libusb-1.0/libusb.h\" outside drivers/",
        "drivers/d.cpp:3: drivers/ may not include \"graphs/g.hpp\"",
        "tests/t.cpp:2: \"libusb.h\" outside drivers/",
        "tests/support/sim_libusb_other/x.cpp:1: \"libusb-1.0/libusb.h\" outside drivers/",
        "drivers/kinect/k.cpp:2: drivers/kinect may not include \"drivers/jaco/j.hpp\"",
        "simulation/world/w.cpp:1: simulation/world may not include \"simulation/devices/d.hpp\"",
        "graphs/nodes/n.cpp:2: graphs/nodes may not include \"graphs/sessions/t.hpp\"",
        "graphs/nodes/n.cpp:3: graphs/nodes may not include \"graphs/tabletop.hpp\"",
    ]
    with tempfile.TemporaryDirectory() as root:
        for rel, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w", encoding="utf-8") as f:
                f.write(text)
        problems = check(root, open(os.devnull, "w", encoding="utf-8"))
    failures = [e for e in expected if not any(p.startswith(e) for p in problems)]
    extra = [p for p in problems if not any(p.startswith(e) for e in expected)]
    for e in failures:
        print("self-test: not reported: " + e)
    for p in extra:
        print("self-test: reported wrongly: " + p)
    print("self-test: %d of %d faults found, %d false reports" % (len(expected) - len(failures), len(expected),
                                                                 len(extra)))
    return 1 if failures or extra else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    default_root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    parser.add_argument("--root", default=default_root, help="checkout to scan (default: %(default)s)")
    parser.add_argument("--self-test", action="store_true", help="check the checker on a scratch tree")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    problems = check(args.root, sys.stdout)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
