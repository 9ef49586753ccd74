#!/usr/bin/python3
"""Install-list guard: everything the project needs comes from .ci/apt-packages.txt.

Fails (and says which file needs what) when one of these is not provided by a package of the list
or of its dependency closure (Depends and Pre-Depends of the installed packages, as
`apt-get install --no-install-recommends` pulls them in):
  python_modules  every module a project .py file imports (ast), except the project's own
  programs        every program a script calls: subprocess argument lists in .py files, command
                  words of the shell scripts (`lfd`, README's bash blocks), launch-prefix and
                  node packages of launch files, `rosrun`/`roslaunch` packages
  ros_packages    every key of every package.xml: a ROS package's manifest is
                  /usr/share/<key>/package.xml; other keys map through .ci/rosdep-keys.txt
A need is "provided" when dpkg says which package owns the file that satisfies it and that package
is in the closure. Scripts under .ci/ run on the CI host, not in the installed root: not scanned.

  check_install_list.py [--junit FILE] [--list FILE]   # exit 1 when something is missing
"""
import argparse
import ast
import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SYSTEM_PATH = "/usr/sbin:/usr/bin:/sbin:/bin"  # dpkg's programs; /usr/local is not a package
SKIP_DIRS = {".git", "build", "devel", ".ci"}
SUBPROCESS_CALLS = {"Popen", "run", "call", "check_call", "check_output", "run_quiet", "execvp"}
# words that run the command after them, and builtins/keywords that run no program at all
SHELL_WRAPPERS = set(
    "if then else elif do while until ! time env exec command nohup sudo { (".split())
SHELL_BUILTINS = set("""fi for done case esac in function select local export set unset shift return
    exit break continue true false read source . cd echo printf eval trap declare readonly wait test
    [ [[ ]] } : pushd popd type builtin let""".split())
TAG_RE = re.compile(r"^(build_|buildtool_|build_export_|exec_|test_|run_|doc_)?depend$")


# ---- the dependency closure of the install list ----------------------------------------------

def installed_packages():
    """{package: (depends, pre_depends)} and {virtual: [providers]} of every installed package."""
    out = subprocess.run(["dpkg-query", "-W", "-f",
                          "${Package}\t${db:Status-Abbrev}\t${Depends}\t${Pre-Depends}\t${Provides}"
                          "\t${Essential}\n"],
                         stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    pkgs, provides, essential = {}, {}, []
    for line in out.splitlines():
        name, status, dep, pre, prov, ess = (line.split("\t") + [""] * 6)[:6]
        if not status.startswith("ii"):
            continue
        if ess == "yes":
            essential.append(name)
        pkgs[name] = ", ".join(d for d in (pre, dep) if d)
        for p in filter(None, (x.strip().split(" ")[0] for x in prov.split(","))):
            provides.setdefault(p, []).append(name)
    return pkgs, provides, essential


def closure(listed, pkgs, provides):
    """Listed packages plus what they pull in; for `a | b`, the first installed alternative."""
    def real(name):
        name = name.split(":")[0]
        if name in pkgs:
            return [name]
        return provides.get(name, [])

    seen, todo = set(), list(listed)
    while todo:
        pkg = todo.pop()
        if pkg in seen:
            continue
        seen.add(pkg)
        for group in filter(None, (g.strip() for g in pkgs.get(pkg, "").split(","))):
            for alt in group.split("|"):
                found = real(alt.strip().split(" ")[0])
                if found:
                    todo.extend(found)
                    break
    return seen


def read_list(path):
    with open(path) as f:
        return [line.split("#")[0].strip() for line in f if line.split("#")[0].strip()]


def owners(paths):
    """{path: {packages}} per dpkg -S (tries each path as given and resolved, with and without
    the /usr prefix of a merged-/usr system)."""
    variants = {}
    for p in paths:
        cands = {p, os.path.realpath(p)}
        cands |= {c[4:] if c.startswith("/usr/") else "/usr" + c for c in list(cands)}
        variants[p] = cands
    every = sorted({c for v in variants.values() for c in v})
    found = {}
    if every:
        out = subprocess.run(["dpkg", "-S"] + every, stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL, universal_newlines=True).stdout
        for line in out.splitlines():
            if line.startswith("diversion ") or ": " not in line:
                continue
            names, path = line.split(": ", 1)
            found.setdefault(path, set()).update(n.strip().split(":")[0] for n in names.split(","))
    return {p: set().union(*(found.get(c, set()) for c in v)) for p, v in variants.items()}


# ---- what the project needs ---------------------------------------------------------------------

def project_files():
    for dirpath, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS]
        for f in files:
            yield os.path.join(dirpath, f)


def rel(path):
    inside = os.path.abspath(path).startswith(ROOT + os.sep)
    return os.path.relpath(path, ROOT) if inside else path


def ros_package_names():
    names = set()
    for f in project_files():
        if os.path.basename(f) == "package.xml":
            names.add(ET.parse(f).getroot().findtext("name").strip())
    return names


def const_list(node):
    """The leading string constants of a list literal (or `[...] + x`), else None."""
    if isinstance(node, ast.BinOp):
        return const_list(node.left)
    if not isinstance(node, (ast.List, ast.Tuple)) or not node.elts:
        return None
    words = []
    for e in node.elts:
        if not (isinstance(e, ast.Constant) and isinstance(e.value, str)):
            break
        words.append(e.value)
    return words or None


def command_lists(tree):
    """Argument lists given to subprocess-like calls or assigned to a `*cmd*` variable."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and node.args:
            func = (node.func.attr if isinstance(node.func, ast.Attribute)
                    else getattr(node.func, "id", ""))
            if func in SUBPROCESS_CALLS:
                words = const_list(node.args[0])
                if words:
                    yield words
        elif isinstance(node, ast.Assign):  # (`cmd += [...]` appends arguments, not a program)
            if any("cmd" in getattr(t, "id", "") for t in node.targets):
                words = const_list(node.value)
                if words:
                    yield words


def ros_tool_needs(words, where, needs):
    """Programs and ROS packages of one command line (`rosrun PKG EXE`, `roslaunch PKG FILE`)."""
    if not words:
        return
    needs["programs"].setdefault(words[0], set()).add(where)
    if words[0] in ("rosrun", "roslaunch", "rostest"):
        rest = list(words[1:])
        while rest and rest[0].startswith("-"):
            rest = rest[2:] if rest[0] in ("-p", "--port") else rest[1:]
        if len(rest) >= 2 and re.match(r"^[A-Za-z]\w*$", rest[0]):
            needs["ros_packages"].setdefault(rest[0], set()).add(where)


def python_needs(path, needs, own_modules):
    with open(path) as f:
        tree = ast.parse(f.read(), path)
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        for name in names:
            if name.split(".")[0] not in own_modules:
                needs["python_modules"].setdefault(name, set()).add(rel(path))
    for words in command_lists(tree):
        ros_tool_needs(words, rel(path), needs)


def shell_commands(text):
    """Command lines (lists of words) of a shell script, roughly as bash sees them."""
    text = text.replace("\\\n", " ")
    functions = set(re.findall(r"^\s*([\w-]+)\s*\(\)", text, re.M))
    for line in text.splitlines():
        lex = shlex.shlex(line, posix=True, punctuation_chars=True)
        lex.commenters = "#"
        lex.wordchars += "$:{}-./=@%+,~*[]!?"
        try:
            tokens = list(lex)
        except ValueError:  # an unbalanced quote on a line of a multi-line string
            continue
        words, at_start, skip, in_array = [], True, False, False
        for i, tok in enumerate(tokens):
            if in_array or (tok in ("(", "()") and i > 0 and tokens[i - 1].endswith("=")):
                in_array = (in_array or tok == "(") and tok != ")"  # `a=(x y)`: words, no command
                continue
            if (at_start and tok == "command" and i + 1 < len(tokens)
                    and tokens[i + 1] in ("-v", "-V")):
                at_start, words = False, None  # `command -v X` looks X up, it does not run it
            if all(c in "();<>|&" for c in tok):
                if set(tok) <= set("<>&") and ("<" in tok or ">" in tok):
                    skip = True  # a redirection: its target is no command
                    continue
                if words:
                    yield words
                words, at_start, skip = [], True, False
                continue
            if skip:
                skip = False
                continue
            if at_start and i + 1 < len(tokens) and tokens[i + 1] == ")":
                continue  # a `case` pattern
            if at_start and (tok in SHELL_BUILTINS or tok in functions - {"as_root"}):
                at_start = False
                words = None  # runs no program (a builtin or one of the script's functions)
            if words is None:
                continue
            if at_start and ("=" in tok.split("/")[0] or tok in SHELL_WRAPPERS or tok == "as_root"
                             or tok.startswith("-")):
                continue  # assignments, wrappers (`env`, `exec`, `as_root`) and their options
            at_start = False
            words.append(tok)
        if words:
            yield words


def shell_needs(text, where, needs):
    for words in shell_commands(text):
        first = words[0]
        if first.startswith("/") or re.match(r"^[A-Za-z][\w.+-]*$", first):
            ros_tool_needs(words, where, needs)


def readme_blocks(path):
    with open(path) as f:
        return re.findall(r"```bash\n(.*?)```", f.read(), re.S)


def launch_needs(path, needs):
    text = open(path).read()
    for pkg in re.findall(r"\$\(find ([\w]+)\)", text):
        needs["ros_packages"].setdefault(pkg, set()).add(rel(path))
    for el in ET.parse(path).getroot().iter():
        if el.tag in ("node", "test") and el.get("pkg"):
            needs["ros_packages"].setdefault(el.get("pkg"), set()).add(rel(path))
        prefix = el.get("launch-prefix")
        if prefix and "$(" not in prefix.split()[0]:
            shell_needs(prefix, rel(path), needs)
    needs["programs"].setdefault("roslaunch" if path.endswith(".launch") else "rostest",
                                 set()).add(rel(path))


def package_xml_needs(path, needs):
    for el in ET.parse(path).getroot():
        if TAG_RE.match(el.tag) and el.text:
            needs["ros_packages"].setdefault(el.text.strip(), set()).add(rel(path))


def collect_needs():
    needs = {"python_modules": {}, "programs": {}, "ros_packages": {}}
    own = ros_package_names()
    own_modules = own | {os.path.basename(f)[:-3] for f in project_files() if f.endswith(".py")}
    # the project's Python packages (lfd_tools): folders with an __init__.py
    own_modules |= {os.path.basename(os.path.dirname(f)) for f in project_files()
                    if os.path.basename(f) == "__init__.py"}
    for f in sorted(project_files()):
        name = os.path.basename(f)
        if f.endswith(".py"):
            python_needs(f, needs, own_modules)
        elif f.endswith((".launch", ".test")):
            launch_needs(f, needs)
        elif name == "package.xml":
            package_xml_needs(f, needs)
        elif os.access(f, os.X_OK) and open(f, "rb").read(64).startswith(b"#!/usr/bin/env bash"):
            shell_needs(open(f).read(), rel(f), needs)
    for block in readme_blocks(os.path.join(ROOT, "README.md")):
        shell_needs(block, "README.md", needs)
    for pkg in own & set(needs["ros_packages"]):
        del needs["ros_packages"][pkg]
    # Python reads bags of these message types (rosbag/genpy import their classes by name, which
    # no import statement shows): a message package named in a package.xml needs its Python too.
    for pkg, users in needs["ros_packages"].items():
        for kind in ("msg", "srv"):
            if os.path.isdir("/usr/share/%s/%s" % (pkg, kind)):
                needs["python_modules"].setdefault("%s.%s" % (pkg, kind), set()).update(users)
    return needs


# ---- which file satisfies each need -------------------------------------------------------------

def module_file(name):
    """The file that provides a module, "builtin", "project", or None when it is not importable."""
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    if spec is None:
        return None
    origin = spec.origin
    if origin in (None, "namespace") and spec.submodule_search_locations:
        origin = list(spec.submodule_search_locations)[0]
    if origin in ("built-in", "frozen") or origin is None:
        return "builtin"
    if os.path.realpath(origin).startswith(ROOT + os.sep):
        return "project"
    return origin


def program_file(name):
    if name.startswith("/"):
        return name if os.path.exists(name) else None
    return shutil.which(name, path=SYSTEM_PATH)


def ros_package_file(key, mapping):
    if key in mapping:
        return ("deb", mapping[key])
    manifest = "/usr/share/%s/package.xml" % key
    return manifest if os.path.exists(manifest) else None


def check(needs, provided, mapping, list_name):
    """{category: [problem lines]}."""
    problems = {k: [] for k in needs}
    files = {}
    for name in needs["python_modules"]:
        files[("python_modules", name)] = module_file(name)
    for name in needs["programs"]:
        files[("programs", name)] = program_file(name)
    for name in needs["ros_packages"]:
        files[("ros_packages", name)] = ros_package_file(name, mapping)
    paths = [f for f in files.values() if isinstance(f, str) and f not in ("builtin", "project")]
    owner = owners(paths)
    for (kind, name), f in sorted(files.items()):
        users = ", ".join(sorted(needs[kind][name]))
        if f in ("builtin", "project"):
            continue
        if f is None:
            problems[kind].append("%s: not found on this machine (needed by %s)" % (name, users))
            continue
        debs = {f[1]} if isinstance(f, tuple) else owner.get(f, set())
        if not debs:
            problems[kind].append("%s: %s belongs to no Debian package (needed by %s)"
                                  % (name, f, users))
        elif not debs & provided:
            hint = " (mapped in .ci/rosdep-keys.txt)" if isinstance(f, tuple) else " (%s)" % f
            problems[kind].append("%s: provided by %s%s, which is not in %s or its dependencies "
                                  "(needed by %s)"
                                  % (name, " or ".join(sorted(debs)), hint, list_name, users))
    return problems


def write_junit(path, problems, counts):
    suite = ET.Element("testsuite", name="install_list", tests=str(len(problems)), errors="0",
                       failures=str(sum(1 for p in problems.values() if p)))
    for kind, lines in problems.items():
        case = ET.SubElement(suite, "testcase", classname="install_list", name=kind)
        if lines:
            fail = ET.SubElement(case, "failure",
                                 message="%d missing of %d" % (len(lines), counts[kind]))
            fail.text = "\n".join(lines)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--list", default=os.path.join(ROOT, ".ci", "apt-packages.txt"))
    ap.add_argument("--keys", default=os.path.join(ROOT, ".ci", "rosdep-keys.txt"))
    ap.add_argument("--junit", help="write a JUnit XML result here")
    ap.add_argument("--verbose", action="store_true", help="print every need and who has it")
    args = ap.parse_args()
    listed = read_list(args.list)
    mapping = dict(line.split()[:2] for line in read_list(args.keys))
    pkgs, provides, essential = installed_packages()
    problems = {"installed": ["%s: listed in %s but not installed" % (p, rel(args.list))
                              for p in listed if p not in pkgs]}
    # Every Debian root has the Essential packages and apt (mmdebstrap's `apt` variant, the base
    # that .ci/fresh-root builds), so they count as installed.
    base = essential + ["apt"]
    provided = closure([p for p in listed + base if p in pkgs], pkgs, provides)
    needs = collect_needs()
    problems.update(check(needs, provided, mapping, rel(args.list)))
    counts = {k: len(v) for k, v in needs.items()}
    counts["installed"] = len(listed)
    if args.verbose:
        for kind, entries in needs.items():
            for name, users in sorted(entries.items()):
                print("%s %s <- %s" % (kind, name, ", ".join(sorted(users))))
    for kind, lines in problems.items():
        print("%-15s %3d checked, %d missing" % (kind, counts[kind], len(lines)))
        for line in lines:
            print("  MISSING " + line)
    if args.junit:
        write_junit(args.junit, problems, counts)
    return 1 if any(problems.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
