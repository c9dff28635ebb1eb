"""Names vulture cannot see used: read by tests/test_dead_code.py, never imported.

vulture matches by name only (``_.name`` marks any attribute, function or variable called
``name`` as used). Each line says why the name is alive. Sections:

- dynamic: reached by a framework (click, pytest, the module protocol, a C library's
  config object) or read by name;
- contract: a field of a result dataclass, or a public API or library function a user
  may call although nothing in the package does.

A package function that only tests or benchmarks call is not whitelisted: it moves to
``tests/support`` (a reference implementation or a test helper) or is deleted.
"""
# ruff: noqa: B018, F821

# ----- dynamic ------------------------------------------------------------------------------
_.pytest_addoption  # analysis/golden_pytest.py: pytest plug-in hook (entry point pytest11)
_.pytest_configure  # analysis/golden_pytest.py: pytest plug-in hook
_.pytest_collect_file  # analysis/golden_pytest.py: pytest plug-in hook
_.runtest  # analysis/golden_pytest.py: pytest.Item protocol method
_.reportinfo  # analysis/golden_pytest.py: pytest.Item protocol method
_.sgtool_golden  # analysis/golden_pytest.py: pytest fixture, requested by name
_.__getattr__  # toolkit/__init__.py: module __getattr__ (PEP 562), the lazy facade
_.__dir__  # toolkit/__init__.py: module __dir__ (PEP 562)
_.list_commands  # toolkit/cli.py: click.Group override
_.get_command  # toolkit/cli.py: click.Group override
_.format_commands  # toolkit/cli.py: click.Group override
_.generate_cmd  # toolkit/commands/scenes.py: click sub-command, registered by decorator
_.check_cmd  # toolkit/commands/scenes.py: click sub-command
_.show_cmd  # toolkit/commands/scenes.py: click sub-command
_.stats_cmd  # toolkit/commands/scenes.py: click sub-command
_.episodes_cmd  # toolkit/commands/scenes.py: click sub-command
_.knowledge_cmd  # toolkit/commands/scenes.py: click sub-command
_.foxglove_layout  # toolkit/commands/export.py: click sub-command
_.serve  # toolkit/commands/llm.py: click sub-command
_.param  # toolkit/commands/options.py: click callback signature (ctx, param, value)
_.default_flow_style  # recorders/exporters/bagwriter.py: ruamel.yaml setting
_.hostnames  # toolkit/llm/server.py: xllamacpp CommonParams field, read by llama.cpp
_.n_ctx  # toolkit/llm/server.py: xllamacpp CommonParams field
_.n_parallel  # toolkit/llm/server.py: xllamacpp CommonParams field
_.cache_ram_mib  # toolkit/llm/server.py: xllamacpp CommonParams field
_.n_threads  # toolkit/llm/server.py: xllamacpp CpuParams field
_.endpoint_props  # toolkit/llm/server.py: xllamacpp CommonParams field
_.verbosity  # toolkit/llm/server.py: xllamacpp CommonParams field
_.cache_prompt  # toolkit/llm/server.py: xllamacpp CommonParams field (the server default)
_.model_alias  # toolkit/llm/server.py: xllamacpp CommonParams field
_._server  # toolkit/llm/server.py: keeps the llama.cpp server object alive
_.holds  # analysis/validity.py: Rule field, rendered into the docs of the rules
_.inference_s  # analysis/paper_tables.py: field looked up by name in analysis/report.py
_.RECORD_BY_SCHEMA  # toolkit/log/schemas.py: schema -> record table, a public lookup
_.PARTIAL_GLOB  # toolkit/log/writer.py: the partial-file pattern named in the module doc

# ----- contract: fields and methods of results that callers may read -------------------------
_.rooms_per_scene  # datasets/scene_stats.py: SceneStats field (printed by `scenes stats`)
_.room_categories_per_scene  # datasets/scene_stats.py: SceneStats field
_.objects_per_scene  # datasets/scene_stats.py: SceneStats field
_.object_categories_per_scene  # datasets/scene_stats.py: SceneStats field
_.max_translation_m  # recorders/importers/odometry.py: DriftReport field
_.replans  # recorders/sim/live_skills.py: skill outcome counter
_.stopped  # recorders/sim/fallback_explore.py: exploration outcome field
_.served  # toolkit/llm/recorded.py: counter of replayed answers
_.remaining  # toolkit/llm/recorded.py: answers not yet replayed
_.prompt_sha256  # toolkit/log/records.py: logged record field
_.invalid_commands  # toolkit/planning/moma/planner.py: counter of rejected LLM commands
_.unexplored_rooms  # toolkit/planning/moma/scene_text.py: EncodedScene field
_.seen_through_entries  # toolkit/scenegraph/builder.py: builder statistics
_.cleared_entries  # toolkit/scenegraph/builder.py: builder statistics
_.cut_edges  # toolkit/scenegraph/room_segmentation.py: segmentation result field
_.cut_nodes  # toolkit/scenegraph/room_segmentation.py: segmentation result field
_.segmentation  # toolkit/scenegraph/builder.py: room-layout result field
_.total_points  # toolkit/mapping/voxels.py: per-instance statistics field
_.view_distance  # toolkit/mapping/voxels.py: per-instance statistics field
_.model_loads  # toolkit/semantics/encoder.py: counter of weight loads
_.best_val_loss  # toolkit/semantics/training.py: TrainResult property
_.scout  # toolkit/planning/utility.py: UtilityParams preset (tests, benchmarks)
_.sbert  # toolkit/planning/utility.py: UtilityParams preset, Table VI (tests, benchmarks)
_.containers  # toolkit/house/spec.py: HouseSpec method, public API
_.children  # toolkit/scenegraph/graph.py: SceneGraph method, public API
_.offered  # toolkit/planning/memory.py: EpisodeMemory method
_.frame_at  # toolkit/log/reader.py: LogReader method, public API
_.content_digest  # analysis/rrd_contents.py: public API (docs/viewers.md; info uses summarize_rrd)
_.write_ids  # toolkit/log/writer.py: LogWriter method, public API (write_frame encodes its own)
_.to_record  # toolkit/scenegraph/instances.py: Instance -> log record
_.excludes  # analysis/intervals.py: Interval method
_.goal_mask  # datasets/episodes.py: EpisodeGeometry method
_.pose_stamped  # recorders/exporters/bagwriter.py: message builder, one per ROS type
_.image  # recorders/exporters/bagwriter.py: message builder
_.compressed  # recorders/exporters/bagwriter.py: message builder
_.ray_depth  # recorders/sim/simulation.py: Simulation method
_.teleport  # recorders/sim/simulation.py: Simulation method (benchmarks/record.py)
_.value_at  # toolkit/mapping/grid.py: OccupancyGrid method
_.integrate_points  # toolkit/mapping/voxels.py: VoxelMap method
_.voxels_of  # toolkit/mapping/voxels.py: VoxelMap method
_.RECORD_NAMES  # toolkit/vocabulary.py: vocabulary table (tests/toolkit/test_vocabulary.py)
_.LOGGED_SKILLS  # toolkit/vocabulary.py: vocabulary table
_.CASES  # replayers/golden.py: the golden cases (tests/golden/regenerate.py)
_.replay_graphs  # replayers/golden.py: public API (sgtool.replay_graphs)
_.write_rerun  # analysis/view_run.py: public API (sgtool.write_rerun)
_.noise_study_config  # analysis/noise_study_api.py: public API (sgtool.noise_study_config)
_.run_noise_study  # analysis/noise_study_api.py: public API (sgtool.run_noise_study)
_.room_check  # toolkit/semantics/everyday_rooms.py: a user scores own priors (module doc)
_.accuracy  # toolkit/semantics/everyday_rooms.py: RoomCheck property (top-1 share)
_.get_metavar  # toolkit/commands/options.py: FiniteFloatRange, called by click for --help
_.source_log  # toolkit/results.py: a run-bench row's log (tools/run_bench_ab.py and others)
