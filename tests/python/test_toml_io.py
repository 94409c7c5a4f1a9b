"""toml_io.write_atomic: whole files only, from any number of threads at once."""
import os
import threading

from dynhet.study.toml_io import read_toml, write_atomic


def test_threads_writing_one_file_at_once(tmp_path):
    # The study's workers write the index at once; a shared temporary name
    # had let one's rename take the other's file away (FileNotFoundError).
    path = str(tmp_path / "index.toml")
    errors = []

    def writer(k):
        try:
            for i in range(200):
                write_atomic(path, f"writer = {k}\ni = {i}\n")
        except Exception as e:  # noqa: BLE001 - any failure is the test's
            errors.append(e)

    ts = [threading.Thread(target=writer, args=(k,)) for k in range(6)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors, errors[:3]
    d = read_toml(path)
    assert d["i"] == 199 and 0 <= d["writer"] < 6  # a whole file, one writer's last
    assert os.listdir(tmp_path) == ["index.toml"]  # no temporary left behind
