// SPDX-License-Identifier: GPL-3.0-or-later
//
// Flamenco 3 job type: renders a frame range of a .blend with the Micropoly
// render engine, in chunks of frames, one Blender process per task.
//
// Install: copy this file into the folder named "scripts" next to the
// flamenco-manager executable, restart the Manager, and refresh the job
// types in Blender's Flamenco add-on. See docs/farm.md.
//
// The workers need Blender with the Micropoly add-on installed (the
// Manager's {blender} variable names that Blender). The add-on is enabled
// with --addons, so it need not be enabled in the workers' preferences.
//
// Output policy: Blender saves each frame into a staging folder private to
// the task's chunk (.partial-<chunk> in the render folder), and a handler
// run by Blender right after the frame's file is written and closed moves it
// into the render folder with an atomic rename. A task killed mid-frame
// leaves its partial file in the staging folder only; the next run of the
// chunk deletes that folder first. After the last frame, the task checks
// that every frame of its chunk was rendered and published by this run, and
// fails (Blender exits non-zero) otherwise: Micropoly reports a failed render
// as an error, but Blender would still exit with status 0.

const JOB_TYPE = {
    label: "Micropoly Render",
    description: "Render a frame range with the Micropoly render engine",
    settings: [
        // Chosen by the artist at submission.
        {
            key: "frames", type: "string", required: true,
            eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
            evalInfo: { showLinkButton: true, description: "Scene frame range" },
            description: "Frames to render, e.g. '1-100' or '1-10, 20-30'",
        },
        {
            key: "chunk_size", type: "int32", default: 4, propargs: { min: 1 }, visible: "submission",
            description: "Frames per task: each task starts Blender and loads the scene once",
        },
        {
            key: "device", type: "string", default: "auto", visible: "submission",
            description: "OpenCL device Micropoly renders on: auto (first GPU, else CPU), cpu, gpu or a device index",
        },
        {
            key: "addon_module", type: "string", default: "micropoly", visible: "submission",
            description: "Module name of the Micropoly add-on on the workers (bl_ext.<repository>.micropoly "
                + "for an add-on installed as a Blender 4.2+ extension)",
        },
        // render_output_root and add_path_components make render_output_path.
        {
            key: "render_output_root", type: "string", subtype: "dir_path", required: true, visible: "submission",
            description: "Folder under which the job's frames are stored, in a sub-folder of the job's own",
        },
        {
            key: "add_path_components", type: "int32", required: true, default: 0,
            propargs: { min: 0, max: 32 }, visible: "submission",
            description: "Number of folder names of the blend file's path to repeat in the render output path",
        },
        {
            key: "render_output_path", type: "string", subtype: "file_path", editable: false,
            eval: "str(Path(abspath(settings.render_output_root), last_n_dir_parts(settings.add_path_components), "
                + "jobname, '{timestamp}', '######'))",
            description: "Where the frames are saved ('######' is the frame number)",
        },

        // Filled in by the Flamenco add-on from the scene.
        { key: "blendfile", type: "string", required: true, visible: "web", description: "The blend file to render" },
        {
            key: "format", type: "string", required: true, visible: "web",
            eval: "C.scene.render.image_settings.file_format",
        },
        { key: "render_engine", type: "string", visible: "hidden", eval: "C.scene.render.engine" },
    ],
};

// Formats Blender writes as one movie file, which cannot be rendered in
// chunks of frames on several workers.
const MOVIE_FORMATS = new Set(["FFMPEG", "AVI_RAW", "AVI_JPEG"]);

function compileJob(job) {
    const settings = job.settings;
    if (settings.render_engine && settings.render_engine !== "MICROPOLY") {
        throw `the scene renders with ${settings.render_engine}; set its render engine to Micropoly`;
    }
    if (MOVIE_FORMATS.has(settings.format)) {
        throw `this job type renders image files, not ${settings.format}: choose an image format`;
    }
    if (!(settings.chunk_size >= 1)) {
        throw `chunk_size must be 1 or more, not ${settings.chunk_size}`;
    }

    const renderOutput = resolveOutputPath(job);
    settings.render_output_path = renderOutput; // the job shows the path its frames went to
    const renderDir = path.dirname(renderOutput);

    for (const chunk of frameChunker(settings.frames, settings.chunk_size)) {
        job.addTask(renderTask(settings, chunk, renderDir, path.basename(renderOutput)));
    }
}

// Replaces {timestamp} in the output path with the job's creation time, so
// that a job submitted again does not overwrite the frames of the first.
function resolveOutputPath(job) {
    const output = job.settings.render_output_path;
    if (!output) {
        throw "the job has no render_output_path";
    }
    return output.replace(/{timestamp}/g, formatTimestampLocal(job.created));
}

// The frame numbers of a chunk as frameChunker writes it ("5", "1-4",
// "1-3,7"): the task checks each of them at the end.
function chunkFrames(chunk) {
    const frames = [];
    for (const part of chunk.split(",")) {
        const item = part.trim();
        if (item === "") continue;
        const bounds = item.split("-").map((n) => parseInt(n, 10));
        const first = bounds[0];
        const last = bounds.length > 1 ? bounds[1] : first;
        if (isNaN(first) || isNaN(last) || last < first) {
            throw `cannot read the frame chunk "${chunk}"`;
        }
        for (let frame = first; frame <= last; frame++) frames.push(frame);
    }
    return frames;
}

// JSON string and number literals are Python literals too: values reach the
// Python expressions below through JSON.stringify, never by pasting text.
function py(value) {
    return JSON.stringify(value);
}

// Runs in Blender after the blend file has loaded, before any frame renders.
function setupExpression(settings, staging, renderDir) {
    return [
        "import bpy, os, shutil, sys, types",
        `DEVICE = ${py(String(settings.device || "auto").trim())}`,
        `STAGING = ${py(staging)}`,
        `FINAL = ${py(renderDir)}`,
        // Micropoly reads MICROPOLY_DEVICE when it creates its renderer, at the
        // first frame; the Flamenco worker gives the command no environment.
        "if DEVICE.lower() in ('', 'auto'):",
        "    os.environ.pop('MICROPOLY_DEVICE', None)",
        "else:",
        "    os.environ['MICROPOLY_DEVICE'] = DEVICE",
        // Without the add-on, -E MICROPOLY only prints an error and Blender
        // would render the frames with another engine.
        "def _engines(cls):",
        "    for sub in cls.__subclasses__():",
        "        yield sub.bl_idname",
        "        yield from _engines(sub)",
        "if 'MICROPOLY' not in set(_engines(bpy.types.RenderEngine)):",
        "    raise RuntimeError('the Micropoly render engine is not registered: is the add-on installed on this worker?')",
        // What an earlier, killed run of this chunk left behind.
        "shutil.rmtree(STAGING, ignore_errors=True)",
        "farm = sys.modules.setdefault('micropoly_farm_task', types.ModuleType('micropoly_farm_task'))",
        "farm.published = set()",
        "def _final_path(scene, frame):",
        "    return os.path.join(FINAL, os.path.relpath(scene.render.frame_path(frame=frame), STAGING))",
        // Blender calls render_write once the frame's file is written and closed.
        "def _publish(scene, *rest):",
        "    staged = scene.render.frame_path(frame=scene.frame_current)",
        "    final = _final_path(scene, scene.frame_current)",
        "    os.makedirs(os.path.dirname(final), exist_ok=True)",
        "    os.replace(staged, final)",
        "    farm.published.add(scene.frame_current)",
        // The Worker picks "Saved: '<file>'" lines out of Blender's output to
        // show the newest frame; Blender's own line names the staging file,
        // gone by the time the Worker reads it, so the final file is named too.
        "    print(\"Saved: '%s' (frame %d published)\" % (final, scene.frame_current), flush=True)",
        "    try:",
        "        os.rmdir(STAGING)  # empty again; Blender makes it anew for the next frame",
        "    except OSError:",
        "        pass",
        "farm.final_path = _final_path",
        "bpy.app.handlers.render_write.append(_publish)",
    ].join("\n");
}

// Runs in Blender after the last frame of the chunk.
function verifyExpression(frames) {
    return [
        "import sys",
        `FRAMES = ${py(frames)}`,
        "farm = sys.modules['micropoly_farm_task']",
        "missing = [f for f in FRAMES if f not in farm.published]",
        "if missing:",
        "    raise RuntimeError('frame(s) %s were not rendered; see the errors above' % missing)",
    ].join("\n");
}

function renderTask(settings, chunk, renderDir, fileName) {
    const staging = path.join(renderDir, `.partial-${chunk.replace(/[^0-9-]+/g, "_")}`);
    const task = author.Task(`render-${chunk}`, "blender");
    task.addCommand(author.Command("blender-render", {
        exe: "{blender}",
        exeArgs: "{blenderArgs}",
        argsBefore: ["--addons", settings.addon_module || "micropoly"],
        blendfile: settings.blendfile,
        // Blender handles these in order: the engine and the checks are in
        // place before --render-frame renders, and the last expression runs
        // after it. --python-exit-code makes a failed check fail the task.
        args: [
            "--python-exit-code", "3",
            "-E", "MICROPOLY",
            "--python-expr", setupExpression(settings, staging, renderDir),
            "--render-output", path.join(staging, fileName),
            "--render-format", settings.format,
            "--render-frame", chunk.replace(/-/g, ".."), // Blender writes ranges as 1..4
            "--python-expr", verifyExpression(chunkFrames(chunk)),
        ],
    }));
    return task;
}
