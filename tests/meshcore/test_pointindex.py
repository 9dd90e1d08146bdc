"""meshcore.pointindex: exact point keys and the numbered index agree with a dictionary."""

import numpy as np

from meshcore.pointindex import PointIndex, point_key, point_keys


def _arrays(seed: int):
    rng = np.random.default_rng(seed)
    pool = rng.integers(-3, 4, size=(12, 2)) * 0.5  # few distinct points: many repeats
    return [pool[rng.integers(0, len(pool), size=n)] for n in (7, 1, 15)]


def test_point_keys_are_the_point_key_of_each_row():
    a = np.array([[0.1, -2.0], [1e300, -0.0], [3.0, 4.0]])
    assert point_keys(a) == [point_key(p) for p in a]
    assert all(type(c) is float for k in point_keys(a) for c in k)


def test_ids_number_equal_points_equally():
    for seed in range(5):
        arrays = _arrays(seed)
        ix = PointIndex(arrays)
        for a, ids in zip(arrays, ix.ids, strict=True):
            assert np.array_equal(ix.points[ids], a)
        keys = [k for a in arrays for k in point_keys(a)]
        assert len(ix) == len(set(keys))
        by_key: dict = {}
        for k, i in zip(keys, np.concatenate(ix.ids), strict=True):
            assert by_key.setdefault(k, i) == i  # one id per key and one key per id
        assert len(set(by_key.values())) == len(by_key)


def test_negative_zero_is_zero():
    ix = PointIndex([np.array([[0.0, 1.0]]), np.array([[-0.0, 1.0]])])
    assert len(ix) == 1 and ix.ids[0][0] == ix.ids[1][0]
    assert ix.find([[-0.0, 1.0]])[0] == 0


def test_find_gives_the_id_or_minus_one():
    arrays = _arrays(7)
    ix = PointIndex(arrays)
    q = np.vstack([arrays[2], [[0.25, 0.0], [99.0, 1.0]]])
    found = ix.find(q)
    assert np.array_equal(found[: len(arrays[2])], ix.ids[2])
    assert found[-2:].tolist() == [-1, -1]
