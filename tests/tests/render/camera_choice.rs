//! Of several file cameras, the one that sees most of the model is used,
//! or the automatic view when none frames the model whole and that view
//! sees more; an index given by the user always wins.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_math::Vec3;
use rtgi_render::recipe::{CameraChoice, FileCameraChoice, choose_camera};
use rtgi_scene::{Camera, Scene};

/// A 4 × 4 grid of quads, 2 wide, facing +Z at the origin.
fn panel() -> Scene {
    let mut obj = String::new();
    for y in 0..=4 {
        for x in 0..=4 {
            obj += &format!("v {} {} 0\n", x as f32 * 0.5 - 1.0, y as f32 * 0.5 - 1.0);
        }
    }
    for y in 0..4 {
        for x in 0..4 {
            let v = |dx: u32, dy: u32| (y + dy) * 5 + x + dx + 1;
            obj += &format!("f {} {} {} {}\n", v(0, 0), v(1, 0), v(1, 1), v(0, 1));
        }
    }
    rtgi_scene::obj::load_from_text(&obj, "", "panel.obj").expect("the panel loads")
}

fn looking(from: Vec3, at: Vec3) -> Camera {
    Camera::look_at(from, at, Vec3::Y, 40f32.to_radians())
}

fn choose(scene: &Scene, index: Option<usize>) -> rtgi_render::recipe::ChosenCamera {
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    choose_camera(scene, accel.as_ref(), &CameraChoice { index, ..CameraChoice::default() }, 1.0).unwrap()
}

#[test]
fn the_camera_that_sees_the_whole_model_is_taken_over_a_close_up_and_one_looking_away() {
    let mut scene = panel();
    let close_up = looking(Vec3::new(0.8, 0.8, 0.3), Vec3::new(0.8, 0.8, 0.0));
    let whole = looking(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let away = looking(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, 10.0));
    scene.cameras = vec![close_up, away, whole];
    let chosen = choose(&scene, None);
    assert_eq!(chosen.camera, whole);
    let Some(FileCameraChoice::SeesMost { index: 2, count: 3, score }) = chosen.file_choice else {
        panic!("{:?}", chosen.file_choice)
    };
    assert!(score.sees_it_whole() && score.seen > 0.95, "{score:?}");
    let note = chosen.file_choice.unwrap().to_string();
    assert!(note.starts_with("camera 2 of the file's 3 (0 to 2)") && note.contains("--camera N"), "{note}");
    // An index given wins, and needs no note.
    let given = choose(&scene, Some(0));
    assert_eq!((given.camera, given.file_choice), (close_up, None));
}

#[test]
fn close_ups_only_give_way_to_the_automatic_view() {
    let mut scene = panel();
    scene.cameras = vec![
        looking(Vec3::new(0.8, 0.8, 0.3), Vec3::new(0.8, 0.8, 0.0)),
        looking(Vec3::new(-0.8, -0.8, 0.3), Vec3::new(-0.8, -0.8, 0.0)),
    ];
    let chosen = choose(&scene, None);
    let Some(FileCameraChoice::Automatic { count: 2, best_score, automatic, .. }) = chosen.file_choice else {
        panic!("{:?}", chosen.file_choice)
    };
    assert!(automatic.seen > 0.9 && best_score.seen < 0.2, "{best_score:?} {automatic:?}");
    assert!(!scene.cameras.contains(&chosen.camera));
}

#[test]
fn a_single_file_camera_is_kept_as_it_is() {
    let mut scene = panel();
    let close_up = looking(Vec3::new(0.8, 0.8, 0.3), Vec3::new(0.8, 0.8, 0.0));
    scene.cameras = vec![close_up];
    let chosen = choose(&scene, None);
    assert_eq!((chosen.camera, chosen.file_choice), (close_up, None));
}
