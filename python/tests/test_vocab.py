"""Vocabularies: learned from Python as by `imitate vocab build`, read,
written, and looked inside."""

from __future__ import annotations

import json

import numpy as np
import pytest

import imitate
from conftest import REPO


@pytest.fixture(scope="module")
def default():
    return imitate.Vocabulary.load("vocab/default.vocab")


def test_the_shipped_vocabulary_is_made_again_byte_for_byte(tmp_path):
    # README: `vocab build mocap -o vocab/default.vocab --labels mocap/labels.csv`.
    vocab = imitate.Vocabulary.build(["mocap"], labels="mocap/labels.csv")
    assert vocab.path is None
    vocab.save(tmp_path / "py.vocab")
    assert (tmp_path / "py.vocab").read_bytes() == (REPO / "vocab/default.vocab").read_bytes()
    assert vocab.path == str(tmp_path / "py.vocab")


def test_options_are_the_cli_flags_and_give_the_same_file(tmp_path, cli):
    takes = ["mocap/wave-h.bvh", "mocap/wave-v.bvh", "mocap/circles.bvh"]
    flags = ["--k", "3", "--seed", "7", "--min-length", "0.3", "--method", "zvc", "--field-neighbors", "6"]
    cli("vocab", "build", *takes, "-o", tmp_path / "cli.vocab", *flags)
    vocab = imitate.Vocabulary.build(takes, k=3, seed=7, min_length=0.3, method="zvc", field_neighbors=6)
    vocab.save(tmp_path / "py.vocab")
    assert (tmp_path / "py.vocab").read_bytes() == (tmp_path / "cli.vocab").read_bytes()
    assert len(vocab) == 3
    # On one thread of its own: the same file.
    one = imitate.Vocabulary.build(takes, k=3, seed=7, min_length=0.3, method="zvc", field_neighbors=6, threads=1)
    one.save(tmp_path / "one.vocab")
    assert (tmp_path / "one.vocab").read_bytes() == (tmp_path / "cli.vocab").read_bytes()


def test_info_is_what_vocab_info_json_prints(default, cli):
    printed = json.loads(cli("vocab", "info", "vocab/default.vocab", "--json").stdout)
    assert default.info() == printed
    assert default.names == [p["name"] for p in printed["primitives"]]


def test_a_primitive_exposes_its_latent_space_field_and_progress(default):
    assert len(default) == len(default.names) > 1
    p = default[0]
    assert default[p.name].name == p.name
    assert [q.name for q in default] == default.names
    d, frames = p.dims, p.latent.shape[0]
    assert p.mean.shape == (43,)
    assert p.basis.shape == (d, 43)
    # The basis is orthonormal (eq. 3).
    assert np.allclose(p.basis @ p.basis.T, np.eye(d), atol=1e-9)
    assert p.latent.shape == p.velocity.shape == (frames, d)
    assert p.phases.shape == (frames,)
    assert 0 < p.speed["p10"] <= p.speed["median"] <= p.speed["p90"]
    # The field is a unit direction that agrees with the training motion.
    directions = p.field(p.latent)
    assert directions.shape == (frames, d)
    assert np.allclose(np.linalg.norm(directions, axis=1), 1.0)
    moving = np.linalg.norm(p.velocity, axis=1) > 0
    agreement = np.sum(directions[moving] * p.velocity[moving], axis=1) / np.linalg.norm(p.velocity[moving], axis=1)
    assert np.median(agreement) > 0.8
    # Progress lies in [0, 1) and follows the training phases.
    progress = p.progress(p.latent)
    assert progress.shape == (frames,) and np.all((0 <= progress) & (progress < 1))
    gap = np.abs(progress - p.phases)
    assert np.median(np.minimum(gap, 1 - gap)) < 0.1
    assert isinstance(p.progress(p.latent[0]), float)
    # Projection and reconstruction are inverse on the latent space.
    assert np.allclose(p.project(p.reconstruct(p.latent[:5])), p.latent[:5])
    with pytest.raises(ValueError, match=rf"\({d},\) or \(N, {d}\)"):
        p.field(np.zeros((3, d + 1)))


def test_out_of_range_and_unknown_options_are_named(tmp_path):
    with pytest.raises(imitate.OptionsError, match="^min_length: ") as caught:
        imitate.Vocabulary.build(["mocap"], min_length=-1.0)
    assert isinstance(caught.value, ValueError) and "--" not in str(caught.value)
    with pytest.raises(imitate.OptionsError, match="^field_neighbors: "):
        imitate.Vocabulary.build(["mocap"], field_neighbors=0)
    with pytest.raises(TypeError, match="min_lenght, speed"):
        imitate.Vocabulary.build(["mocap"], min_lenght=0.3, speed=2)
    with pytest.raises(TypeError, match="k: cannot use a str"):
        imitate.Vocabulary.build(["mocap"], k="three")


def test_a_truncated_vocabulary_raises_the_message_the_cli_prints(tmp_path, cli):
    cut = tmp_path / "cut.vocab"
    cut.write_bytes((REPO / "vocab/default.vocab").read_bytes()[:500])
    with pytest.raises(imitate.VocabularyError) as caught:
        imitate.Vocabulary.load(cut)
    assert caught.value.path == str(cut)
    printed = cli("vocab", "info", cut, check=False)
    assert printed.returncode == 1
    assert printed.stderr.strip() == f"imitate: error: {caught.value}"


def test_a_missing_take_raises_a_bvh_error_naming_it(tmp_path):
    with pytest.raises(imitate.BvhError) as caught:
        imitate.Vocabulary.build([tmp_path / "none.bvh"])
    assert caught.value.path == str(tmp_path / "none.bvh")


def test_a_vocabulary_of_another_format_version_is_refused(tmp_path):
    data = bytearray((REPO / "vocab/default.vocab").read_bytes())
    # The format version: a little-endian u32 after the 14-byte magic.
    data[14:18] = (99).to_bytes(4, "little")
    newer = tmp_path / "newer.vocab"
    newer.write_bytes(bytes(data))
    with pytest.raises(imitate.VocabularyError, match="format version 99") as caught:
        imitate.Vocabulary.load(newer)
    assert caught.value.path == str(newer)
