#!/usr/bin/env python3
"""Static cost of S per evaluation in compiled SPIR-V: hairlut.glsl's direction interface (both
filters) and its sampling, and hairlut_generic.glsl's, against pbrt-v4's HairBxDF::f in GLSL (tests/gpu/pbrt_hair_f.comp).

Each shader is compiled by glslangValidator and optimised by spirv-opt -O (every function inlined
into main; the same main around each: read wo and wi, write S). Counted in main: instructions that
compute (not labels, merge declarations, phis, plain branches, composite extracts, access chains),
texture reads, GLSL.std.450 calls by name, and each loop's instructions from its header to its merge
(a nested loop's inside its parent's). A static count: an if's two branches both count, a loop's
body once.

Usage: spirv_cost.py SOURCE_DIR (needs glslangValidator and spirv-opt, spirv-dis on PATH)
"""
import collections
import re
import subprocess
import sys
import tempfile
from pathlib import Path

MAIN = """#version 450
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
#include "hairlut.glsl"
layout(set = 0, binding = 2, std140) uniform Materials { HairlutMaterial material; };
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, std430) writeonly buffer Values { vec4 values[]; };
layout(push_constant) uniform Push { uint count; uint mode; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  values[i] = vec4(hairlut_eval(material, points[2 * i].xyz, points[2 * i + 1].xyz), 0.0);
}
"""
SAMPLE = MAIN.replace('#include "hairlut.glsl"', '#define HAIRLUT_SAMPLING 1\n#include "hairlut.glsl"').replace(
    "values[i] = vec4(hairlut_eval(material, points[2 * i].xyz, points[2 * i + 1].xyz), 0.0);",
    "HairlutSample s = hairlut_sample(material, hairlut_at(material, points[2 * i].xyz), points[2 * i + 1].xyz);\n"
    "  values[i] = vec4(s.weight, s.pdf);")
GENERIC = """#version 450
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
#define HAIRLUT_GENERIC_SET_BINDING 2
#define HAIRLUT_GENERIC_DATA_BINDING 5
#include "hairlut_generic.glsl"
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, std430) writeonly buffer Values { vec4 values[]; };
layout(push_constant) uniform Push { uint count; uint mode; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 c = points[4 * i + 2], d = points[4 * i + 3];
  values[i] = vec4(hairlut_generic_eval(HairlutFiber(c.xyz, c.w, d.x, d.y), points[4 * i].xyz, points[4 * i + 1].xyz), 0.0);
}
"""
SKIP = re.compile(r"OpLabel|OpLoopMerge|OpSelectionMerge|OpFunction|OpVariable|OpPhi|OpBranch\b|OpCompositeExtract|OpAccessChain")
CHEAP = {"FMax", "FMin", "FClamp", "Fma", "FAbs", "Floor", "Round", "SMin", "SMax", "UMin", "UMax"}


def cost(source, defines, work):
    spv, opt = work / "a.spv", work / "o.spv"
    subprocess.run(["glslangValidator", "--quiet", "-V", "--target-env", "vulkan1.1", *defines, "-o", str(spv), str(source)], check=True)
    subprocess.run(["spirv-opt", "-O", str(spv), "-o", str(opt)], check=True)
    text = subprocess.run(["spirv-dis", "--no-header", str(opt)], check=True, capture_output=True, text=True).stdout.split("\n")
    body = text[next(i for i, line in enumerate(text) if "OpFunction " in line and "%main" in line):]
    labels = {m.group(1): i for i, line in enumerate(body) if (m := re.match(r"\s*(%\w+) = OpLabel", line))}
    counted = [0 if SKIP.search(line) or not line.strip() else 1 for line in body]
    ext = collections.Counter(m.group(1) for line in body if (m := re.search(r"OpExtInst %\w+ %\w+ (\w+)", line)))
    loops = []
    for i, line in enumerate(body):
        if m := re.search(r"OpLoopMerge (%\w+)", line):
            header = max(j for j in labels.values() if j <= i)
            loops.append(sum(counted[header:labels[m.group(1)]]))
    texture = sum(1 for line in body if re.search(r"OpImage(Sample|Fetch)", line))
    calls = ", ".join(f"{k} {v}" for k, v in sorted(ext.items()) if k not in CHEAP)
    return sum(counted), texture, calls, loops


def main():
    source = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[2])
    with tempfile.TemporaryDirectory() as d:
        work = Path(d)
        (work / "eval.comp").write_text(MAIN)
        (work / "sample.comp").write_text(SAMPLE)
        (work / "generic.comp").write_text(GENERIC)
        include = f"-I{source / 'lib' / 'shaders'}"
        rows = [("hairlut.glsl hairlut_eval, hardware filter", cost(work / "eval.comp", [include, "-DHAIRLUT_FILTER=0"], work)),
                ("hairlut.glsl hairlut_eval, explicit filter", cost(work / "eval.comp", [include, "-DHAIRLUT_FILTER=1"], work)),
                ("hairlut_sampling.glsl hairlut_at + hairlut_sample, hardware filter", cost(work / "sample.comp", [include, "-DHAIRLUT_FILTER=0"], work)),
                ("hairlut_generic.glsl hairlut_generic_eval (buffer reads in loops)", cost(work / "generic.comp", [include], work)),
                ("pbrt-v4 HairBxDF::f (tests/gpu/pbrt_hair_f.comp)", cost(source / "tests" / "gpu" / "pbrt_hair_f.comp", [], work))]
    print("| shader | instructions | texture reads | GLSL.std.450 calls | loops (instructions header to merge) |")
    print("|---|---|---|---|---|")
    for name, (n, texture, calls, loops) in rows:
        print(f"| {name} | {n} | {texture} | {calls} | {', '.join(map(str, loops))} |")


if __name__ == "__main__":
    main()
