#!/usr/bin/env python3
"""Load-time stand-ins for shared libraries a GPU bundle does not carry (tools/gpu_bundle.sh).

OpenImageIO links some 200 libraries (video codecs, OpenVDB, DICOM, GDAL, ...) for file formats
rtpg never reads or writes; with them its renderer and tests are 400 MB, more than travels to the
workplace's GPU machines. OpenImageIO is linked with BIND_NOW, so every symbol it imports must
resolve when it loads, used or not. For each library left behind this writes a library of the
same soname that defines exactly the symbols the carried files import from it, with their
versions (functions as a trap, constructors and destructors as nothing, version queries as
the string "stand-in", data as zeroed storage of the real size), and builds
it with the C compiler. A call into a stand-in stops the program with SIGILL: a bundle that reaches
one uses a format it was not meant to, and the run says so instead of computing something wrong.

Usage: gpu_stub_libs.py OUT_DIR --carried FILE... --stub LIB...
"""
import argparse
import os
import re
import subprocess
import sys


def readelf(*args):
    return subprocess.run(["readelf", "-W", *args], check=True, capture_output=True,
                          text=True).stdout


def soname(path):
    match = re.search(r"\(SONAME\)\s+Library soname: \[(.+?)\]", readelf("-d", path))
    return match.group(1) if match else os.path.basename(path)


SYMBOL = re.compile(r"^\s*\d+:\s+([0-9a-f]+)\s+(\d+|0x[0-9a-f]+)\s+(\w+)\s+(\w+)\s+(\w+)\s+"
                    r"(\w+)\s+(\S+?)(?:\s+\(\d+\))?\s*$")


def dynamic_symbols(path):
    """(name, version or '', default version?, type, bind, size, defined?) per dynamic symbol."""
    out = []
    for line in readelf("--dyn-syms", path).splitlines():
        m = SYMBOL.match(line)
        if not m:
            continue
        _, size, kind, bind, _, ndx, name = m.groups()
        if bind == "LOCAL" or not name:
            continue
        version, default = "", True
        if "@@" in name:
            name, version = name.split("@@", 1)
        elif "@" in name:
            name, version = name.split("@", 1)
            default = ndx == "UND"
        out.append((name, version, default, kind, bind, int(size, 0), ndx != "UND"))
    return out


def version_definitions(path):
    names = []
    for line in readelf("-V", path).splitlines():
        m = re.search(r"Flags: (\S+)\s+Index: \d+\s+Cnt: \d+\s+Name: (\S+)", line)
        if m and m.group(1) != "BASE":
            names.append(m.group(2))
    return names


# Itanium C++ ABI names of complete and base object constructors and destructors.
CONSTRUCTOR = re.compile(r"(C[12]|D[012])E(v|[A-Z]|R|P|S|i|j|m|l|b|d|f|c|h)")


def stub_source(imports, defined):
    """Assembly defining each imported (name, version) that the real library defines."""
    # The trap writes the stand-in's name to stderr (write(2, rsi, rdx)), then stops.
    lines = [".text", "__rtpg_stub_trap:", "  mov $2, %edi", "  mov $1, %eax", "  syscall",
             "  ud2"]
    data = [".data"]
    names = [".section .rodata", "__rtpg_stub_version:", '  .asciz "stand-in"']
    count = 0
    for name, version in sorted(imports):
        match = defined.get((name, version)) or (defined.get((name, "")) if not version else None)
        if not match:
            continue
        kind, size, default = match
        label = f"__rtpg_stub_{count}"
        count += 1
        target = lines
        if kind in ("FUNC", "IFUNC", "NOTYPE") and CONSTRUCTOR.search(name):
            # Static objects of the left-behind library (a codec registry, say) are built at
            # load and destroyed at exit: their constructors and destructors do nothing.
            target += [f".globl {label}", f".type {label}, @function", f"{label}:", "  ret"]
        elif kind in ("FUNC", "IFUNC", "NOTYPE") and "version" in name.lower():
            # OpenImageIO asks every format library for its version when it first lists its
            # plugins: a stand-in answers with the string "stand-in" (a non-zero number to a
            # caller that wants one).
            target += [f".globl {label}", f".type {label}, @function", f"{label}:",
                       "  lea __rtpg_stub_version(%rip), %rax", "  ret"]
        elif kind in ("FUNC", "IFUNC", "NOTYPE"):
            message = f"gpu bundle: called {name}, a stand-in (tools/gpu_stub_libs.py)\\n"
            names += [f"{label}_name:", f'  .ascii "{message}"']
            target += [f".globl {label}", f".type {label}, @function", f"{label}:",
                       f"  lea {label}_name(%rip), %rsi", f"  mov ${len(message) - 1}, %edx",
                       "  jmp __rtpg_stub_trap"]
        elif kind == "OBJECT":
            target = data
            target += [f".globl {label}", f".type {label}, @object", f".size {label}, {size}",
                       ".balign 16", f"{label}:", f"  .zero {max(size, 1)}"]
        else:  # TLS and the like: nothing rtpg's carried files were seen to import
            raise SystemExit(f"gpu_stub_libs: {name} is a {kind} symbol; no stand-in for it")
        if version:
            target.append(f".symver {label}, {name}{'@@' if default else '@'}{version}")
        else:
            target.append(f".set {name}, {label}")
            target.append(f".globl {name}")
    return "\n".join(lines + data + names) + "\n", count


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--carried", nargs="+", required=True)
    parser.add_argument("--stub", nargs="+", required=True)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    imports = set()
    for path in args.carried:
        for name, version, _, _, _, _, is_defined in dynamic_symbols(path):
            if not is_defined:
                imports.add((name, version))
    for lib in args.stub:
        defined = {}
        for name, version, default, kind, _, size, is_defined in dynamic_symbols(lib):
            if is_defined:
                defined[(name, version)] = (kind, size, default)
        source, count = stub_source(imports, defined)
        name = soname(lib)
        stem = os.path.join(args.out, name)
        with open(stem + ".s", "w") as f:
            f.write(source)
        versions = version_definitions(lib)
        with open(stem + ".map", "w") as f:
            f.write("".join(f"{v} {{ }};\n" for v in versions) or "{ };\n")
        subprocess.run(["cc", "-shared", "-nostdlib", f"-Wl,-soname,{name}",
                        f"-Wl,--version-script={stem}.map", "-o", stem, stem + ".s"], check=True)
        os.remove(stem + ".s")
        os.remove(stem + ".map")
        print(f"gpu_stub_libs: {name}: {count} symbols", file=sys.stderr)


if __name__ == "__main__":
    main()
