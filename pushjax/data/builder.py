"""The TFDS builder of the push datasets: array_record files, read back with `tfds.data_source`, no TensorFlow.

One :class:`PushEffects` builder (dataset name ``push_effects``) with a config per experiment, scale and testbed
profile, named ``<experiment>_<scale>`` on the default ``realistic`` testbed and ``<experiment>_<scale>_ideal`` on
the ``ideal`` one (see :mod:`pushjax.data.configs`). Building simulates the push sequences the config needs
(MuJoCo testbed, :mod:`pushjax.sim`, with the config's profile) into a raw cache in the MIT layout, cuts them into
examples (:mod:`pushjax.data.examples`) and serialises them in worker processes (all cores by default), and writes
one array_record file set per split::

    builder = PushEffects(config="data_efficiency_smoke", data_dir=DIR)      # seed=3 for another seed
    # config="data_efficiency_smoke_ideal": the same on the ideal testbed
    builder.download_and_prepare()
    sources = tfds.data_source("push_effects/data_efficiency_smoke", data_dir=DIR, download=False)

With Apache Beam instead of the process pool (``pip install 'pushjax[beam]'``), simulation, rendering and writing
are Beam transforms that any runner can run (TFDS's Beam support: the runner and its options come in the download
config)::

    builder.download_and_prepare(download_config=tfds.download.DownloadConfig(
        beam_runner="DirectRunner", beam_options=PipelineOptions(["--direct_num_workers=2"])))

Both paths write the same records in the same order (by key: sequence, then example). The files are the same too
while TFDS's Beam writer keeps a split in one shard (under 128 MiB); beyond, it cuts more shards than the process
pool, which fills shards of ``EXAMPLES_PER_SHARD``.

Resuming: a finished dataset is not rebuilt (:func:`build` logs that it reused it, with its version and folder),
and the simulated sequences are cached as MIT files under ``<data_dir>/push_effects_raw/<testbed>/seed<seed>/``
(shared by all experiments and scales of a testbed and seed, since the pushes drawn for a smaller scale are a
prefix of those of a larger one; never shared between testbeds), so an interrupted build only redoes the examples
of the dataset it was writing. The same config and seed give the same bytes.

Versions (``PushEffects.RELEASE_NOTES``): every 1.0.0 dataset and its raw cache ``push_effects_raw/seed<seed>``
was simulated with the profile now called ``ideal``; 2.0.0 simulates with ``realistic`` by default, and reads
neither.

A raw folder given by the user (``raw_dir``, e.g. real MIT files) is read-only to pushjax: it must hold every
file the config plans, else the build stops with :class:`IncompleteRawDirError` before writing anything; only
pushjax's own cache is simulated into.

The configuration (image size, glimpse size, horizon, ...) is stored in each dataset's metadata
(``builder.info.metadata["config"]``) and available as ``builder.builder_config.dataset``.
"""

from __future__ import annotations

import collections
import concurrent.futures
import dataclasses
import functools
import multiprocessing
import os
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import tensorflow_datasets as tfds
import tqdm
from absl import logging
from array_record.python.array_record_module import ArrayRecordWriter
from tensorflow_datasets.core import example_serializer
from tensorflow_datasets.core import writer as tfds_writer
from tensorflow_datasets.proto import tf_example_pb2

from pushjax.data import configs
from pushjax.data.examples import ALL_FIELDS, make_renderer, sequence_examples
from pushjax.mit.files import load_push
from pushjax.sim.dataset import PushJob, record_push, recorded_file_problem
from pushjax.sim.testbed import DEFAULT_PROFILE

DATASET_NAME = "push_effects"
RAW_DIR_NAME = "push_effects_raw"
EXAMPLES_PER_SHARD = 20_000


class IncompleteRawDirError(ValueError):
    """A user's ``raw_dir`` that lacks files the config plans; the message counts them and names the first."""


class DatasetFolderError(ValueError):
    """A dataset folder that TFDS cannot read: its ``dataset_info.json`` is damaged or was written by another version
    of the dataset; the message (``data_dir: <folder> ...``) names the folder and what is wrong."""


@dataclasses.dataclass(eq=False)
class PushEffectsConfig(tfds.core.BuilderConfig):
    """A TFDS builder config carrying the :class:`pushjax.data.configs.DatasetConfig` it builds."""

    dataset: configs.DatasetConfig | None = None


def _builder_config(dataset: configs.DatasetConfig) -> PushEffectsConfig:
    return PushEffectsConfig(
        name=dataset.name, dataset=dataset,
        description=f"{dataset.experiment} experiment at {dataset.scale} scale on the {dataset.testbed} testbed "
                    f"(seed {dataset.seed}); see pushjax.data.configs.")


class PushEffects(tfds.core.GeneratorBasedBuilder):
    """Examples of pushes in the MuJoCo testbed (depth image, pusher, action, object motion, physical state).

    Args:
      seed: dataset seed; a seed other than 0 builds ``<config>_seed<seed>`` next to the seed-0 datasets.
      min_test_sequences: 0, or the config's test splits grown to this many sequences, a test-only dataset
        ``<config>_test<N>`` (``pushjax.data.configs.plan_grown_test_splits``).
      raw_dir: root of a raw (MIT layout) folder to read the sequences from, read-only: building raises
        :class:`IncompleteRawDirError` (counting the missing files, naming the first) unless it holds every file
        the config plans, and never writes into it. None (default): pushjax's own cache
        ``<data_dir>/push_effects_raw/<testbed>/seed<seed>``, where missing sequences are simulated with the
        config's testbed profile.
      workers: worker processes for simulation and rendering (default: all cores; 1: this process). Workers are
        spawned, so a script that builds with several workers must do so under ``if __name__ == "__main__":``.
        Not used by a Beam build (a download config with ``beam_runner`` or ``beam_options``), whose runner
        decides.
      progress: show a progress bar per split (process-pool builds).
      **kwargs: as for ``tfds.core.GeneratorBasedBuilder`` (``config``, ``data_dir``, ...); the file format
        defaults to ``array_record``.
    """

    VERSION = tfds.core.Version("3.0.0")
    RELEASE_NOTES = {
        "1.0.0": "First release: six experiments at smoke, cpu and paper scale.",
        "2.0.0": "Pushes simulated with the realistic testbed profile (pushjax.sim.testbed, calibrated against the "
                 "paper) by default; the ideal profile (every 1.0.0 dataset's) as configs <experiment>_<scale>_ideal. "
                 "Raw cache per profile (push_effects_raw/<testbed>/seed<seed>). Records written with their "
                 "features in a canonical (name) order, so the same seed gives the same bytes in any process.",
        "3.0.0": "data_efficiency and viewpoint gain a validation split (test_pushes_per_object further sequences per "
                 "object), for learning curves and the choice of the training schedule.",
    }
    BUILDER_CONFIGS = [_builder_config(dataset) for dataset in configs.all_configs()]
    DEFAULT_CONFIG_NAME = f"data_efficiency_{configs.DEFAULT_SCALE}"

    def __init__(self, *, seed: int = 0, min_test_sequences: int = 0, raw_dir: str | os.PathLike | None = None,
                 workers: int | None = None, progress: bool = True, **kwargs):
        for name, value in (("seed", seed), ("min_test_sequences", min_test_sequences)):
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise ValueError(f"{name}: expected an integer >= 0, got {value!r}")
        if workers is not None and (not isinstance(workers, int) or workers < 1):
            raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")
        config = kwargs.get("config") or self.DEFAULT_CONFIG_NAME
        if seed or min_test_sequences:
            name = config if isinstance(config, str) else config.dataset.name
            base = {c.name: c for c in self.BUILDER_CONFIGS}.get(name)
            if base is None:
                raise ValueError(f"config: expected one of {', '.join(c.name for c in self.BUILDER_CONFIGS)}, "
                                 f"got {name!r}")
            kwargs["config"] = _builder_config(dataclasses.replace(base.dataset, seed=seed,
                                                                   min_test_sequences=min_test_sequences))
        kwargs.setdefault("file_format", "array_record")
        try:
            super().__init__(**kwargs)
        except Exception as error:  # TFDS reports a bad dataset_info.json in many ways
            folder = getattr(self, "_data_dir", None)
            if folder is None:  # failed before it looked at the folder: not a folder's fault
                raise
            detail = " ".join(f"{type(error).__name__}: {error}".split())
            raise DatasetFolderError(
                f"data_dir: {folder} is not a readable {DATASET_NAME} {self.VERSION} dataset ({detail}); delete the "
                "folder to build the dataset again") from error
        self._raw_dir = Path(raw_dir) if raw_dir is not None else (
            Path(self.data_dir).parents[2] / RAW_DIR_NAME / self.builder_config.dataset.testbed / f"seed{seed}")
        self._simulate_missing = raw_dir is None
        self._workers = workers or os.cpu_count() or 1
        self._progress = progress
        self._pool = None

    @property
    def dataset_config(self) -> configs.DatasetConfig:
        return self.builder_config.dataset

    @property
    def raw_dir(self) -> Path:
        """Where the raw sequences are read from (and, for pushjax's own cache, simulated into)."""
        return self._raw_dir

    def _info(self) -> tfds.core.DatasetInfo:
        dataset = self.builder_config.dataset
        return tfds.core.DatasetInfo(
            builder=self,
            description="Pushes in a MuJoCo stand-in for the MIT Push Dataset: depth image (or point cloud) "
                        "before the push, pusher position and motion, object motion over the horizon, and the "
                        "ground-truth physical state (Kloss, Schaal & Bohg).",
            features=example_features(dataset.image_size),
            # Stored in key order, as generated (not shuffled): the process pool and Beam write the same order.
            disable_shuffling=True,
            metadata=tfds.core.MetadataDict(config=dataclasses.asdict(dataset)),
        )

    def _generate_splits(self, dl_manager, download_config) -> list[tfds.core.SplitInfo]:
        if download_config.beam_runner is not None or download_config.beam_options is not None:
            # TFDS runs the Beam pipeline of `_split_generators` and writes each split with its BeamWriter, which
            # sorts the examples by key (no shuffling, see `_info`). An in-process runner (the DirectRunner's
            # default) renders in this process, whose renderers are closed afterwards.
            try:
                return super()._generate_splits(dl_manager, download_config)
            finally:
                _close_renderers()
        # TFDS's own writer buffers a split in memory and spills beyond 1 GB through tf.io.gfile, i.e. needs
        # TensorFlow; each split is streamed into array_record shards here instead, in generation order.
        if self._workers == 1:
            try:
                return self._write_splits(dl_manager)
            finally:
                _close_renderers()
        # A process pool that fails (BrokenProcessPool) rather than hangs when a worker dies.
        with concurrent.futures.ProcessPoolExecutor(self._workers, mp_context=multiprocessing.get_context("spawn"),
                                                    initializer=_init_worker) as pool:
            self._pool = pool
            try:
                return self._write_splits(dl_manager)
            finally:
                self._pool = None

    def _write_splits(self, dl_manager) -> list[tfds.core.SplitInfo]:
        infos = []
        plan = self._checked_plan()
        for split, ids in plan.splits.items():
            template = self._get_filename_template(split)
            shard_lengths, num_bytes, writer = [], 0, None
            for record in self._generate_examples(plan, ids, split):
                if writer is None or shard_lengths[-1] == EXAMPLES_PER_SHARD:
                    if writer is not None:
                        writer.close()
                    shard_lengths.append(0)
                    writer = ArrayRecordWriter(os.fspath(_partial_shard(template, len(shard_lengths) - 1)),
                                               "group_size:1")
                writer.write(record)
                shard_lengths[-1] += 1
                num_bytes += len(record)
            if writer is None:
                raise ValueError(f"config: split {split!r} of {self.builder_config.name} has no examples")
            writer.close()
            for index in range(len(shard_lengths)):
                os.replace(_partial_shard(template, index),
                           template.sharded_filepath(shard_index=index, num_shards=len(shard_lengths)))
            infos.append(tfds.core.SplitInfo(name=split, shard_lengths=shard_lengths, num_bytes=num_bytes,
                                             filename_template=template))
        return infos

    def _example_writer(self) -> tfds_writer.ExampleWriter:
        return _CanonicalExampleWriter(self.info.file_format)

    def _checked_plan(self) -> configs.SplitPlan:
        """The split plan; raises `IncompleteRawDirError` when a given raw folder lacks planned files."""
        plan = configs.plan_splits(self.builder_config.dataset, self._raw_dir)
        if not self._simulate_missing:
            missing = [job.path for job in plan.jobs if not job.path.is_file()]
            if missing:
                raise IncompleteRawDirError(
                    f"raw_dir: {len(missing)} of {len(plan.jobs)} files planned for {self.builder_config.name} "
                    f"are missing under {self._raw_dir} (first: {missing[0]}); a raw folder you give is read-only "
                    "to pushjax: add the files, or leave raw_dir out to simulate into pushjax's own cache")
        return plan

    def _split_generators(self, dl_manager, pipeline):
        """Split name -> Beam PCollection of (key, example), for TFDS's Beam build (``pipeline`` given by TFDS)."""
        return _beam_splits(pipeline, self.builder_config.dataset, self._checked_plan(), self._simulate_missing)

    def _generate_examples(self, plan: configs.SplitPlan, ids: tuple[int, ...], split: str) -> Iterator[bytes]:
        """(TFDS's hook, called by `_write_splits` only.) The stored records of the split's sequences, in key order,
        serialised by the worker processes (`sequence_task`): this process only writes them."""
        dataset = self.builder_config.dataset
        tasks = [(dataset, plan.jobs[sequence_id], sequence_id, self._simulate_missing) for sequence_id in ids]
        if self._pool is None:
            results = map(sequence_task, tasks)
        else:
            results = _ordered_map(self._pool, sequence_task, tasks, ahead=4 * self._workers)
        with tqdm.tqdm(total=len(tasks), disable=not self._progress, unit="seq", desc=f"{dataset.name} {split}") as bar:
            for records in results:
                yield from records
                bar.update()


def _beam_splits(pipeline, dataset: configs.DatasetConfig, plan: configs.SplitPlan, simulate_missing: bool) -> dict:
    """Split name -> Beam PCollection of (key, example) for TFDS to write.

    Each planned sequence is recorded (or read) and cut into examples once, on whichever worker the runner picks,
    then goes to every split that holds it (the alternative training splits share sequences).
    """
    beam = tfds.core.lazy_imports.apache_beam
    sequence_ids = sorted(set().union(*plan.splits.values()))
    sequences = (
        pipeline
        | "PlannedSequences" >> beam.Create([(i, plan.jobs[i]) for i in sequence_ids])
        | "SpreadOverWorkers" >> beam.Reshuffle()  # Create alone may leave every sequence on one worker.
        | "SimulateOrRead" >> beam.Map(_recorded, simulate_missing=simulate_missing)
        | "MakeExamples" >> beam.MapTuple(lambda sequence_id, job: (
            sequence_id, recorded_sequence_examples(dataset, job, sequence_id))))
    return {
        name: (sequences
               | f"Select_{name}" >> beam.Filter(lambda sequence, ids=frozenset(ids): sequence[0] in ids)
               | f"Key_{name}" >> beam.FlatMap(lambda sequence: keyed_examples(dataset, *sequence)))
        for name, ids in plan.splits.items()}


def _recorded(sequence: tuple[int, PushJob], simulate_missing: bool) -> tuple[int, PushJob]:
    """(sequence id, recording job), once the job's raw file exists (see :func:`record_missing`)."""
    record_missing(sequence[1], simulate_missing)
    return sequence


class _CanonicalExampleWriter(tfds_writer.ExampleWriter):
    """TFDS's shard writer (used by Beam builds), writing :func:`canonical_record` records."""

    def write(self, path, examples):
        return super().write(path, ((key, canonical_record(record)) for key, record in examples))


def canonical_record(record: bytes) -> bytes:
    """A serialized ``tf.train.Example`` with its features in name order.

    Protobuf writes a map's entries (an example's features) in an order that varies from process to process;
    sorted, a record's bytes depend only on its content, whichever process serialized it.
    """
    return tf_example_pb2.Example.FromString(record).SerializeToString(deterministic=True)


def _ordered_map(pool: concurrent.futures.Executor, function, tasks: list, ahead: int) -> Iterator:
    """``pool.map`` with at most ``ahead`` tasks in flight, so results never pile up in memory."""
    pending = collections.deque()
    for task in tasks:
        pending.append(pool.submit(function, task))
        if len(pending) >= ahead:
            yield pending.popleft().result()
    while pending:
        yield pending.popleft().result()


def _partial_shard(template, index: int) -> Path:
    """Where shard ``index`` is written before the number of shards is known."""
    return Path(template.sharded_filepath(shard_index=index, num_shards=1)).with_name(
        f"{template.dataset_name}-{template.split}.partial-{index:05d}")


# Per-process renderers, by (camera, image size, object, surface).
_RENDERERS: dict = {}


def _init_worker() -> None:
    os.environ.setdefault("MUJOCO_GL", "egl")
    # Mesa's software rasteriser (llvmpipe) renders in the calling thread: its worker threads cost more than
    # they save on small images, and the workers already use every core.
    os.environ.setdefault("LP_NUM_THREADS", "0")
    # One XLA thread per worker: the workers already use every core.
    os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " --xla_cpu_multi_thread_eigen=false "
                               "intra_op_parallelism_threads=1").strip()


def _close_renderers() -> None:
    while _RENDERERS:
        _RENDERERS.popitem()[1].close()


def sequence_rng(dataset: configs.DatasetConfig, job: PushJob) -> np.random.Generator:
    """The generator of a sequence's windows, transforms and pusher moves (independent of split and worker)."""
    return np.random.default_rng([dataset.seed, zlib.crc32(job.path.name.encode("utf-8"))])


def keyed_examples(dataset: configs.DatasetConfig, sequence_id: int,
                   examples: dict[str, np.ndarray]) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
    """(key, example) of a sequence's stacked examples (field -> [E, ...], E = ``examples_per_sequence``).

    The key, ``sequence_id * E + index``, is the example's place among all examples of the split plan: a split's
    examples are stored in key order.
    """
    first = sequence_id * dataset.examples_per_sequence
    for index, example in enumerate(_unstacked(dataset, examples)):
        yield first + index, example


def _unstacked(dataset: configs.DatasetConfig, examples: dict[str, np.ndarray]) -> Iterator[dict[str, np.ndarray]]:
    """The examples of a sequence's stacked examples (field -> [E, ...]), one by one."""
    for index in range(dataset.examples_per_sequence):
        yield {name: value[index] for name, value in examples.items()}


def record_missing(job: PushJob, simulate_missing: bool) -> None:
    """Records the sequence's raw file (MuJoCo testbed) unless it exists; in pushjax's own cache also records
    again a file that must be (`pushjax.sim.dataset.recorded_file_problem`: recorded with a flung plate).

    Args:
      job: the sequence's recording job.
      simulate_missing: whether a missing file may be simulated, i.e. the raw folder is pushjax's own cache.

    Raises:
      IncompleteRawDirError: the raw file is missing from a folder that may not be written.
    """
    if not job.path.exists():
        if not simulate_missing:
            raise IncompleteRawDirError(f"raw_dir: {job.path} is missing (a raw folder you give is read-only)")
        record_push(job)
    elif simulate_missing and (problem := recorded_file_problem(job)):
        logging.warning("recording again: %s", problem)
        record_push(job)


def example_features(image_size: int) -> tfds.features.FeaturesDict:
    """The features of one example: `ALL_FIELDS` with images of ``image_size`` x ``image_size`` px."""
    sizes = {"H": image_size, "W": image_size}
    return tfds.features.FeaturesDict({
        name: tfds.features.Tensor(
            shape=tuple(sizes.get(dim, dim) for dim in field.shape), dtype=field.dtype, doc=field.doc,
            # Images as raw bytes: the default float list serialises element by element (ms per image).
            encoding=tfds.features.Encoding.BYTES if "H" in field.shape else tfds.features.Encoding.NONE)
        for name, field in ALL_FIELDS.items()})


@functools.cache
def _features_and_serializer(image_size: int) -> tuple[tfds.features.FeaturesDict, example_serializer.ExampleSerializer]:
    features = example_features(image_size)
    return features, example_serializer.ExampleSerializer(features.get_serialized_info())


def example_records(dataset: configs.DatasetConfig, examples: dict[str, np.ndarray]) -> list[bytes]:
    """The stored records (`canonical_record`) of a sequence's stacked examples (field -> [E, ...]), in order: the
    same bytes in whichever process makes them."""
    features, serializer = _features_and_serializer(dataset.image_size)
    return [canonical_record(serializer.serialize_example(features.encode_example(example)))
            for example in _unstacked(dataset, examples)]


def sequence_task(task: tuple[configs.DatasetConfig, PushJob, int, bool]) -> list[bytes]:
    """Worker: reads the sequence's raw file (recording it first if missing and allowed), returns its examples'
    records (`example_records`: serialised in the workers, the writing process only writes).

    Args:
      task: (dataset config, recording job, sequence id, whether a missing raw file may be simulated, i.e. the
        raw folder is pushjax's own cache).

    Raises:
      IncompleteRawDirError: the raw file is missing from a folder that may not be written.
    """
    dataset, job, sequence_id, simulate_missing = task
    record_missing(job, simulate_missing)
    return example_records(dataset, recorded_sequence_examples(dataset, job, sequence_id))


def recorded_sequence_examples(dataset: configs.DatasetConfig, job: PushJob, sequence_id: int) -> dict[str, np.ndarray]:
    """The examples (field -> [E, ...]) of a sequence whose raw file exists, rendered by this process's renderer."""
    push = load_push(job.path)
    key = (dataset.camera, dataset.image_size, job.params.shape, job.params.surface)
    if key not in _RENDERERS:
        _RENDERERS[key] = make_renderer(dataset, job.params.shape, job.params.surface)
    return sequence_examples(push, dataset, _RENDERERS[key], sequence_id, sequence_rng(dataset, job))


def config_name(experiment: str, scale: str = configs.DEFAULT_SCALE, testbed: str = DEFAULT_PROFILE) -> str:
    """The builder config of a dataset, seed aside: ``<experiment>_<scale>``, ``_<testbed>`` unless the default."""
    return configs.get_config(experiment, scale, testbed=testbed).name


def build(experiment: str, scale: str = configs.DEFAULT_SCALE, data_dir: str | os.PathLike | None = None,
          seed: int = 0, testbed: str = DEFAULT_PROFILE, workers: int | None = None, progress: bool = True,
          raw_dir: str | os.PathLike | None = None, beam_runner=None, beam_options=None,
          min_test_sequences: int = 0) -> PushEffects:
    """Builds (or finds) one dataset and returns its builder; see :class:`PushEffects` for the arguments.

    ``testbed`` names the testbed profile (``pushjax.sim.testbed.PROFILES``). ``beam_runner`` (a runner or its
    name, e.g. ``"DirectRunner"``) and ``beam_options`` (``apache_beam.options.pipeline_options.PipelineOptions``)
    build with Apache Beam instead of the process pool; both None (default): the process pool. Logs (absl, INFO)
    whether it reused a finished dataset or built it, with the dataset's name, version and folder.
    """
    builder = PushEffects(config=config_name(experiment, scale, testbed), data_dir=data_dir, seed=seed,
                          min_test_sequences=min_test_sequences, workers=workers, progress=progress, raw_dir=raw_dir)
    reused = builder.is_prepared()
    builder.download_and_prepare(download_config=tfds.download.DownloadConfig(beam_runner=beam_runner,
                                                                            beam_options=beam_options))
    logging.info("dataset %s version %s: %s %s", dataset_name(experiment, scale, seed, testbed, min_test_sequences),
                 builder.version, "reused from" if reused else "built in", builder.data_dir)
    return builder


def dataset_name(experiment: str, scale: str = configs.DEFAULT_SCALE, seed: int = 0,
                 testbed: str = DEFAULT_PROFILE, min_test_sequences: int = 0) -> str:
    """The ``tfds.data_source`` name of a dataset, e.g. ``push_effects/data_efficiency_cpu``,
    ``push_effects/data_efficiency_cpu_ideal/seed=3`` or ``push_effects/velocities_cpu/min_test_sequences=150``."""
    kwargs = [f"{name}={value}" for name, value in (("seed", seed), ("min_test_sequences", min_test_sequences))
              if value]
    return f"{DATASET_NAME}/{config_name(experiment, scale, testbed)}" + (f"/{','.join(kwargs)}" if kwargs else "")


def load(experiment: str, scale: str = configs.DEFAULT_SCALE, data_dir: str | os.PathLike | None = None,
         seed: int = 0, testbed: str = DEFAULT_PROFILE, split: str | None = None, min_test_sequences: int = 0):
    """The built dataset's ``tfds.data_source``: split name -> random-access source (or one source for ``split``).

    Each element is a dict of NumPy arrays with the fields of ``pushjax.data.schema.FIELDS`` plus
    ``pushjax.data.examples.EXTRA_FIELDS``. Nothing is built: a missing dataset raises.
    """
    return tfds.data_source(dataset_name(experiment, scale, seed, testbed, min_test_sequences), data_dir=data_dir,
                            split=split, download=False)
