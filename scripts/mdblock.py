"""Replace the marked block of a generated Markdown file (BENCHMARKS.md,
COMPAT.md), leaving the rest as it is; shared by the scripts that write one."""
import os, re


def replace_block(path, begin, end, block, title):
    """Put `block` (which starts with `begin` and ends with `end`) in place of
    the old one in `path`, or append it (a new file starts with `title`);
    written through a temporary file, so a killed run leaves the old file."""
    old = open(path).read() if os.path.exists(path) else title + "\n"
    if begin in old:
        new = re.sub(re.escape(begin) + r".*?" + re.escape(end), lambda _: block, old, flags=re.S)
    else:
        new = old.rstrip() + "\n\n" + block + "\n"
    with open(path + ".tmp", "w") as f:
        f.write(new)
    os.replace(path + ".tmp", path)
