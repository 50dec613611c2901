"""Writing a figure or an animation into a directory redres writes: the file is made under a fresh private
directory beside its final name (tempfile.mkdtemp: created exclusively, mode 0700), then renamed into place. A
symbolic link, directory or other non-regular file at the final name is refused with a message, never followed or
replaced, and a failed save leaves the old file."""
import os
import shutil
import stat
import tempfile


class OutputError(RuntimeError):
    pass


def require_replaceable(path):
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISREG(st.st_mode):
        kind = "a symbolic link" if stat.S_ISLNK(st.st_mode) else "a directory" if stat.S_ISDIR(st.st_mode) \
            else "not a regular file"
        raise OutputError(f"cannot write {path}: it is {kind}; redres writes only regular files and never replaces "
                          "or follows anything else")


def save_output(path, save):
    """Calls save(temporary_path) and renames the result onto path."""
    require_replaceable(path)
    directory = os.path.dirname(os.path.abspath(path))
    base = os.path.basename(path)
    private = tempfile.mkdtemp(prefix="." + base + ".tmp.", dir=directory)
    try:
        target = os.path.join(private, base)  # the same extension, which matplotlib's writers go by
        save(target)
        require_replaceable(path)
        os.replace(target, path)
    finally:
        shutil.rmtree(private, ignore_errors=True)  # the directory mkdtemp made for this save, and what is in it
