#!/usr/bin/env python3
"""Copies the shared-library closure of some executables into one folder (scripts/gpu/bundle.sh).

Libraries named in --stub (sonames) are replaced by generated stubs with the same soname that
define only the symbols the kept libraries import from them (functions return a pointer to
zeroed memory, an empty string to the version queries OpenImageIO makes, and its static
initialisers call DCMTK's; data is zeroed; symbol versions kept), so their own dependency trees stay behind: OpenImageIO pulls in
~330 MB of codecs (ffmpeg, OpenVDB, DICOM, GDAL through OpenCV's videoio, ...) that shadowfilter
never uses, and what travels to the device machine is limited to 64 MiB.
Usage: bundle_libs.py OUT_DIR --stub SONAME... -- EXE...
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SEARCH = ["/lib/x86_64-linux-gnu", "/usr/lib/x86_64-linux-gnu", "/lib64", "/usr/lib64", "/usr/lib"]
SKIP = re.compile(r"^(libpocl|linux-vdso)")


def needed(path):
    out = subprocess.run(["readelf", "-dW", path], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)


def resolve(name):
    for d in SEARCH:
        p = os.path.join(d, name)
        if os.path.exists(p):
            return p
    raise SystemExit(f"bundle_libs: cannot find {name}")


def dynsyms(path):
    """(name, version or '', default version?, defined?, type, size, bind) per dynamic symbol."""
    out = subprocess.run(["readelf", "--dyn-syms", "-W", path], capture_output=True, text=True,
                         check=True).stdout
    syms = []
    for line in out.splitlines():
        f = line.split()
        if len(f) < 8 or not f[0].endswith(":") or not f[0][:-1].isdigit():
            continue
        size = int(f[2], 0) if f[2].startswith("0x") else int(f[2])
        typ, bind, ndx, name = f[3], f[4], f[6], f[7]
        m = re.match(r"^(.*?)(@@?)([^@\s]+)(?: \(\d+\))?$", name)
        ver, default = "", True
        if m:
            name, ver, default = m.group(1), m.group(3), m.group(2) == "@@"
        if len(f) > 8 and f[8].startswith("("):
            pass
        syms.append((name, ver, default, ndx != "UND", typ, size, bind))
    return syms


def make_stub(soname, imports, src_lib, out_path):
    """imports: {name: version} the kept libraries need from this library."""
    defs = {(s[0], s[1]): s for s in dynsyms(src_lib) if s[3]}
    byname = {}
    for s in defs.values():
        byname.setdefault(s[0], s)
    asm, versions = [".bss", ".balign 64", "__sf_zeros:", ".zero 4096", ".text"], {}
    for name, ver in sorted(imports.items()):
        s = defs.get((name, ver)) or byname.get(name)
        typ, size = (s[4], s[5]) if s else ("FUNC", 0)
        asm.append(f".globl {name}")
        if typ in ("OBJECT", "TLS", "COMMON"):
            tls = typ == "TLS"
            asm += [f'.section {".tbss" if tls else ".bss"},"aw{"T" if tls else ""}",@nobits',
                    ".balign 16", f".type {name},@{'tls_object' if tls else 'object'}",
                    f".size {name},{max(size, 1)}", f"{name}:", f".zero {max(size, 1)}", ".text"]
        else:
            asm += [f".type {name},@function", f"{name}:", "lea __sf_zeros(%rip),%rax", "ret"]
        versions.setdefault(ver, []).append(name)
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "stub.S"), "w") as fh:
            fh.write("\n".join(asm) + "\n")
        cmd = ["gcc", "-shared", "-nostdlib", "-o", out_path, os.path.join(tmp, "stub.S"),
               f"-Wl,-soname,{soname}"]
        named = [v for v in versions if v]
        if named:
            vs = os.path.join(tmp, "stub.map")
            with open(vs, "w") as fh:
                for j, v in enumerate(named):
                    names = versions[v] + (versions.get("", []) if j == 0 else [])
                    fh.write(f"{v} {{ global: {' '.join(n + ';' for n in names)} }};\n")
            cmd.append(f"-Wl,--version-script={vs}")
        subprocess.run(cmd, check=True)


def main():
    args = sys.argv[1:]
    out = args[0]
    sep = args.index("--")
    stubs = set(args[args.index("--stub") + 1:sep]) if "--stub" in args else set()
    exes = args[sep + 1:]
    os.makedirs(out, exist_ok=True)
    kept, seen, order = {}, set(), []
    todo = list(exes)
    while todo:
        p = todo.pop()
        for n in needed(p):
            if n in seen or SKIP.match(n):
                continue
            seen.add(n)
            order.append(n)
            if n in stubs:
                continue
            kept[n] = resolve(n)
            todo.append(kept[n])
    # What the kept libraries (and the executables) import from each stubbed library: symbols
    # they leave undefined that no kept library defines.
    defined = set()
    for n, p in kept.items():
        defined.update(s[0] for s in dynsyms(p) if s[3])
    for s in stubs & seen:
        src = resolve(s)
        offered = {x[0] for x in dynsyms(src) if x[3]}
        imports = {}
        for p in list(kept.values()) + exes:
            if s not in needed(p):
                continue
            for x in dynsyms(p):
                if not x[3] and x[0] in offered and x[0] not in defined:
                    imports[x[0]] = x[1]
        make_stub(s, imports, src, os.path.join(out, s))
        print(f"stub {s}: {len(imports)} symbols")
    for n, p in kept.items():
        shutil.copy(os.path.realpath(p), os.path.join(out, n))
    total = sum(os.path.getsize(os.path.join(out, n)) for n in os.listdir(out))
    print(f"{len(kept)} libraries, {len(stubs & seen)} stubs, {total / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
