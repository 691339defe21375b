"""The known log noise is dropped, and nothing else."""

import logging

from pushjax import logs


def test_only_the_known_messages_are_dropped(caplog):
    logs.quiet_known_noise()
    logs.quiet_known_noise()  # idempotent
    assert sum(isinstance(f, logs._DropMessages) for f in logging.getLogger("absl").filters) == 1
    with caplog.at_level(logging.INFO):
        logging.getLogger("absl").warning("Given directory is read only=%s", "/some/model")
        logging.getLogger("absl").warning("Given directory does not exist: %s", "/some/model")
        logging.getLogger("jax._src.xla_bridge").info("Unable to initialize backend 'tpu': INTERNAL: no libtpu.so")
        logging.getLogger("jax._src.xla_bridge").info("Unable to initialize backend 'cuda': no GPU")
        logging.getLogger("jax._src.xla_bridge").error("Given directory is read only")  # another logger's: kept
    messages = [record.getMessage() for record in caplog.records]
    assert messages == ["Given directory does not exist: /some/model",
                        "Unable to initialize backend 'cuda': no GPU", "Given directory is read only"]
