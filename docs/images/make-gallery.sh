#!/usr/bin/env bash
# docs/images/gallery.png: every shared scene and glTF model, each rendered
# exactly as 'rtgi render SCENE' renders it with no options. Run from the
# workspace root after 'cargo build --release'; the shared scenes are found
# at ../shared/scenes, or where RTGI_SCENES points.
set -euo pipefail
cd "$(dirname "$0")/../.."
scenes=${RTGI_SCENES:-../shared/scenes}
rtgi=${RTGI:-target/release/rtgi}
"$rtgi" gallery \
    "$scenes/bunny/stanford-bunny.obj" \
    "$scenes/dragon/dragon-100k.obj" \
    "$scenes/cornell-box/CornellBox-Original.obj" \
    "$scenes/cornell-box/CornellBox-Mirror.obj" \
    "$scenes/cornell-box/CornellBox-Empty-RG.obj" \
    "$scenes/sponza-dabrovic/sponza.obj" \
    "$scenes/conference/conference.obj" \
    "$scenes/gltf/Box/glTF/Box.gltf" \
    "$scenes/gltf/BoxTextured/glTF/BoxTextured.gltf" \
    "$scenes/gltf/Cameras/glTF/Cameras.gltf" \
    "$scenes/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf" \
    "$scenes/gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf" \
    "$scenes/gltf/TransmissionTest/glTF/TransmissionTest.gltf" \
    "$scenes/gltf/TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb" \
    "$scenes/gltf/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf" \
    scenes/cornell-box.toml \
    --width 256 --height 192 --columns 4 -o docs/images/gallery.png "$@"
