//! The keyboard: steering the player's creature, new rounds, and live tuning of what the
//! paper's figures 8 and 9 vary (the level policy and the radii of influence).

use bevy::prelude::*;

use super::GameSettings;
use super::player::{BaseConfig, NewRound, PlayerIntent};
use super::scene::ColourByLevel;
use super::view::FollowCamera;
use simlod::config::SimConfig;
use simlod::lod::LevelPolicy;

/// The keys, as the HUD lists them: only those that do something under `policy`.
pub fn controls_help(policy: LevelPolicy) -> String {
    let mut keys = vec!["WASD/arrows steer", "Enter new round", "C colours", "L level policy"];
    if policy.uses_puck_radius() {
        keys.push("[ ] puck radius");
    }
    if policy.uses_camera_radius() {
        keys.push("- = camera radius");
    }
    if policy.uses_frame_budget() {
        keys.push("9 0 frame budget");
    }
    keys.extend(["P figures", "Esc quit"]);
    keys.join("   ")
}

/// Whether the HUD shows the developer's figures: frame times, the budget's prediction against
/// the time measured, and the last switches' pops.
#[derive(Resource, Debug, Default)]
pub struct ShowFigures(pub bool);

/// A short message on screen after a key press, with the time it goes away.
#[derive(Resource, Debug, Default)]
pub struct Notice {
    /// The message, shown above the keys in the HUD.
    pub text: String,
    /// When it goes away: seconds of real time since the game started.
    pub until_s: f32,
}

/// How long a notice stays.
const NOTICE_S: f32 = 4.0;

/// Steering keys, relative to the view: up is away from the camera.
fn read_steering_keys(
    keys: Res<ButtonInput<KeyCode>>,
    camera: Query<&GlobalTransform, With<FollowCamera>>,
    mut intent: ResMut<PlayerIntent>,
) {
    let pressed = |a: KeyCode, b: KeyCode| keys.pressed(a) || keys.pressed(b);
    let mut ask = Vec2::ZERO;
    ask.y += f32::from(u8::from(pressed(KeyCode::KeyW, KeyCode::ArrowUp)));
    ask.y -= f32::from(u8::from(pressed(KeyCode::KeyS, KeyCode::ArrowDown)));
    ask.x += f32::from(u8::from(pressed(KeyCode::KeyD, KeyCode::ArrowRight)));
    ask.x -= f32::from(u8::from(pressed(KeyCode::KeyA, KeyCode::ArrowLeft)));
    let (forward, right) = camera.single().map_or((Vec2::NEG_Y, Vec2::X), |t| {
        let f = t.forward().as_vec3();
        let f = Vec2::new(f.x, f.z).normalize_or(Vec2::NEG_Y);
        (f, Vec2::new(-f.y, f.x))
    });
    let wanted = (forward * ask.y + right * ask.x).normalize_or_zero();
    if intent.0 != wanted {
        intent.0 = wanted;
    }
}

fn read_game_keys(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time<Real>>,
    mut rounds: MessageWriter<NewRound>,
    mut exit: MessageWriter<AppExit>,
    mut colour_by_level: ResMut<ColourByLevel>,
    mut show_figures: ResMut<ShowFigures>,
    settings: Res<GameSettings>,
    mut config: ResMut<SimConfig>,
    mut base: ResMut<BaseConfig>,
    mut notice: ResMut<Notice>,
) {
    let mut say = |text: String| {
        *notice = Notice {
            text,
            until_s: time.elapsed_secs() + NOTICE_S,
        }
    };
    if keys.just_pressed(KeyCode::Enter) {
        rounds.write(NewRound);
    }
    if keys.just_pressed(KeyCode::Escape) {
        exit.write(AppExit::Success);
    }
    if keys.just_pressed(KeyCode::KeyC) {
        colour_by_level.0 = !colour_by_level.0;
        say(format!(
            "colour by level {}",
            if colour_by_level.0 { "on" } else { "off" }
        ));
    }
    if keys.just_pressed(KeyCode::KeyP) {
        show_figures.0 = !show_figures.0;
        say(format!(
            "frame times and switch pops {}",
            if show_figures.0 { "shown" } else { "hidden" }
        ));
    }
    if keys.just_pressed(KeyCode::KeyL) {
        // Every policy there is, in turn, live: each creature moves to its new level in its
        // next flight window (paper 3.4); later rounds keep the policy.
        let all = LevelPolicy::ALL;
        let now = all.iter().position(|&p| p == config.scenario.level_policy).unwrap_or(0);
        let next = all[(now + 1) % all.len()];
        config.scenario.level_policy = next;
        base.scenario.level_policy = next;
        say(format!("level policy {}", next.name()));
    }
    // The puck's radius of influence (figure 8) and the camera's (figure 9), live: the
    // rules decide levels at every decision, so the change shows at once (paper 3.4).
    let step = settings.hud.radius_step_m;
    for (key, which, by) in [
        (KeyCode::BracketLeft, Radius::Puck, -step),
        (KeyCode::BracketRight, Radius::Puck, step),
        (KeyCode::Minus, Radius::Camera, -step),
        (KeyCode::Equal, Radius::Camera, step),
    ] {
        if keys.just_pressed(key) {
            let radius = (*which.of(&mut config) + by).max(0.0);
            *which.of(&mut config) = radius;
            *which.of(&mut base) = radius;
            say(format!(
                "{} radius of influence {radius:.0} m{}",
                which.name(),
                if which.used_by(config.scenario.level_policy) {
                    String::new()
                } else {
                    format!(" (the {} policy does not use it)", config.scenario.level_policy.name())
                }
            ));
        }
    }
    // The budget policy's frame budget, live: it is spent anew at every decision.
    for (key, by) in [
        (KeyCode::Digit9, -settings.hud.budget_step_ms),
        (KeyCode::Digit0, settings.hud.budget_step_ms),
    ] {
        if keys.just_pressed(key) {
            let budget = (config.rules.budget.frame_budget_ms + by).max(0.0);
            config.rules.budget.frame_budget_ms = budget;
            base.rules.budget.frame_budget_ms = budget;
            say(format!(
                "frame budget {budget:.1} ms{}",
                if config.scenario.level_policy.uses_frame_budget() {
                    String::new()
                } else {
                    format!(" (the {} policy does not use it)", config.scenario.level_policy.name())
                }
            ));
        }
    }
}

/// The radii of influence the keys change.
#[derive(Clone, Copy)]
enum Radius {
    Puck,
    Camera,
}

impl Radius {
    fn of(self, config: &mut SimConfig) -> &mut f32 {
        match self {
            Radius::Puck => &mut config.rules.influence.puck_radius_m,
            Radius::Camera => &mut config.rules.camera.radius_m,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Radius::Puck => "puck",
            Radius::Camera => "camera",
        }
    }

    fn used_by(self, policy: LevelPolicy) -> bool {
        match self {
            Radius::Puck => policy.uses_puck_radius(),
            Radius::Camera => policy.uses_camera_radius(),
        }
    }
}

/// A policy as the command line spells it.
pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Notice>()
        .init_resource::<ShowFigures>()
        .add_systems(Update, (read_steering_keys, read_game_keys));
}

#[cfg(test)]
mod tests {
    use super::*;
    use simlod::config::load_file;
    use simlod::{SimPlugin, lod::LevelPolicy};
    use std::path::Path;

    fn app_with_keys(policy: LevelPolicy) -> App {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
        let mut config = SimConfig::load(&root.join("scenarios/default.ron"), &root).unwrap();
        config.scenario.level_policy = policy;
        let looks = load_file(&root.join(crate::GAME_FILE)).unwrap();
        let mut app = App::new();
        app.add_plugins(MinimalPlugins)
            .add_plugins(SimPlugin::new(config))
            .init_resource::<ButtonInput<KeyCode>>()
            .insert_resource(ColourByLevel(true))
            .insert_resource(GameSettings(looks));
        super::super::player::plugin(&mut app);
        plugin(&mut app);
        app.update();
        app
    }

    fn press(app: &mut App, key: KeyCode) {
        let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
        keys.release_all();
        keys.clear();
        keys.press(key);
        app.update();
    }

    #[test]
    fn radius_keys_change_the_running_rules_and_the_next_rounds() {
        let mut app = app_with_keys(LevelPolicy::Combined);
        let radii = |app: &App, of: fn(&SimConfig) -> f32| {
            (
                of(app.world().resource::<SimConfig>()),
                of(app.world().resource::<BaseConfig>()),
            )
        };
        let puck = |c: &SimConfig| c.rules.influence.puck_radius_m;
        let camera = |c: &SimConfig| c.rules.camera.radius_m;
        let (puck_before, camera_before) = (radii(&app, puck).0, radii(&app, camera).0);
        press(&mut app, KeyCode::BracketRight);
        press(&mut app, KeyCode::BracketRight);
        press(&mut app, KeyCode::Minus);
        assert_eq!(radii(&app, puck), (puck_before + 2.0, puck_before + 2.0));
        assert_eq!(radii(&app, camera), (camera_before - 1.0, camera_before - 1.0));
        for _ in 0..40 {
            press(&mut app, KeyCode::BracketLeft);
        }
        assert_eq!(radii(&app, puck).0, 0.0, "a radius stops at zero");
        assert!(
            app.world()
                .resource::<Notice>()
                .text
                .contains("puck radius of influence 0 m")
        );
    }

    #[test]
    fn the_policy_key_changes_the_running_policy_without_a_new_round() {
        let mut app = app_with_keys(LevelPolicy::Combined);
        let serials = |app: &mut App| {
            let world = app.world_mut();
            let mut s: Vec<u32> = world
                .query::<&simlod::creature::Creature>()
                .iter(world)
                .map(|c| c.serial)
                .collect();
            s.sort_unstable();
            s
        };
        let before = serials(&mut app);
        press(&mut app, KeyCode::KeyL);
        let policies = |app: &App| {
            (
                app.world().resource::<SimConfig>().scenario.level_policy,
                app.world().resource::<BaseConfig>().scenario.level_policy,
            )
        };
        assert_eq!(policies(&app), (LevelPolicy::Budget, LevelPolicy::Budget));
        assert_eq!(serials(&mut app), before, "the same creatures: no new round");
        press(&mut app, KeyCode::KeyL);
        assert_eq!(policies(&app), (LevelPolicy::AllPointMass, LevelPolicy::AllPointMass));
        assert!(app.world().resource::<Notice>().text.contains("all-point-mass"));
    }

    #[test]
    fn a_radius_key_says_when_the_policy_does_not_use_that_radius() {
        let mut app = app_with_keys(LevelPolicy::Camera);
        press(&mut app, KeyCode::BracketRight);
        let notice = &app.world().resource::<Notice>().text;
        assert!(notice.contains("does not use it"), "{notice}");
        press(&mut app, KeyCode::Equal);
        let notice = &app.world().resource::<Notice>().text;
        assert!(!notice.contains("does not use it"), "{notice}");
    }
}
