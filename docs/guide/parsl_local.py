# parsl_local.py: hexdem's studies on Parsl, on this one machine.
#   hexdem sweep --vary v0=0.2,0.4 --out results/speeds --parsl parsl_local.py
# Each run is one task of a worker; Parsl writes its logs into the study's folder
# (runinfo/), unless run_dir is set here. tests/test_studies.py runs this file.
import os

from parsl.config import Config
from parsl.executors import HighThroughputExecutor
from parsl.providers import LocalProvider

config = Config(
    executors=[
        HighThroughputExecutor(
            label="local",
            # the workers are on this machine
            address="127.0.0.1",
            # runs at once: one per CPU (each run on one rank; with
            # --ranks-per-run K, divide by K)
            max_workers_per_node=os.cpu_count(),
            # a worker pool that dies is replaced and its runs retried
            block_error_handler=False,
            provider=LocalProvider(init_blocks=1, min_blocks=1, max_blocks=1),
        )
    ],
    retries=1,  # each run is tried up to twice
    # Parsl starts the block at its strategy's first look: after half a second
    # rather than its default 5 s
    strategy_period=0.5,
)
