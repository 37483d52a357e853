//! The HUD: the player's score, the frame rate and the simulation's cost per frame,
//! collisions and falls, the level policy; the creatures at each level, with a key to the
//! level colours; the game-over banner; the keys; and any problem with an edited asset file.

use bevy::app::RunFixedMainLoopSystems;
use bevy::prelude::*;
use std::fmt::Write;
use std::time::Instant;

use super::GameSettings;
use super::controls::{Notice, ShowFigures, controls_help};
use super::player::Round;
use super::reload::Problems;
use super::scene::{ColourByLevel, srgb};
use simlod::SimClock;
use simlod::config::SimConfig;
use simlod::lod::PopTally;
use simlod::lod::{BudgetTally, Lod};
use simlod::outcome::{Summary, summarize};

/// Wall time of the frame's simulation ticks, and the frame rate, both smoothed.
#[derive(Resource, Debug, Default)]
struct Timing {
    ticks_started: Option<Instant>,
    /// When the last frame's ticks ended: the frame rate is measured by the wall clock, even
    /// when `--screenshot` sets the game's time per frame.
    last_frame: Option<Instant>,
    sim_ms_per_frame: f32,
    /// The same per 1/30 s of simulated motion (a decision's ticks), as the budget counts it.
    sim_ms_per_decision: f32,
    /// The tick the last frame's ticks ended at.
    last_tick: u64,
    frames_per_s: f32,
}

/// The world's counts, read once a frame.
#[derive(Resource, Debug)]
struct Counts(Summary);

#[derive(Component, Clone, Copy, PartialEq, Eq)]
enum HudText {
    Stats,
    /// A level's name and how many creatures are at it, beside its colour.
    Level(Lod),
    Banner,
    Problems,
    Help,
}

/// A square of a level's colour in the HUD's key (paper figures 5 and 6 colour by level).
#[derive(Component)]
struct Swatch(Lod);

fn start_timing(mut timing: ResMut<Timing>) {
    timing.ticks_started = Some(Instant::now());
}

/// Measured around the fixed loop, outside the simulation: the simulation never reads the
/// clock.
fn stop_timing(
    settings: Res<GameSettings>,
    clock: Res<SimClock>,
    mut timing: ResMut<Timing>,
    mut budget: ResMut<BudgetTally>,
) {
    let Some(start) = timing.ticks_started.take() else {
        return;
    };
    let now = Instant::now();
    let dt = timing
        .last_frame
        .replace(now)
        .map_or(0.0, |last| (now - last).as_secs_f32());
    let ease = 1.0 - (-dt / settings.hud.smoothing_s).exp();
    let sim_ms = start.elapsed().as_secs_f32() * 1000.0;
    timing.sim_ms_per_frame += (sim_ms - timing.sim_ms_per_frame) * ease;
    let ticks = clock
        .tick
        .saturating_sub(std::mem::replace(&mut timing.last_tick, clock.tick));
    if ticks > 0 {
        let per_decision = sim_ms * clock.ticks_per_decision as f32 / ticks as f32;
        budget.measured_us = Some(per_decision * 1e3);
        timing.sim_ms_per_decision += (per_decision - timing.sim_ms_per_decision) * ease;
    }
    if dt > 0.0 {
        timing.frames_per_s += (1.0 / dt - timing.frames_per_s) * ease;
    }
}

fn count(world: &mut World) {
    let summary = summarize(world, 0.0);
    world.insert_resource(Counts(summary));
}

fn panel() -> (BackgroundColor, TextColor) {
    (
        BackgroundColor(Color::srgba(0.0, 0.0, 0.0, 0.55)),
        TextColor(Color::WHITE),
    )
}

fn spawn_hud(mut commands: Commands, settings: Res<GameSettings>) {
    let size = settings.hud.font_size_px;
    let at = |top: Option<f32>, bottom: Option<f32>| Node {
        position_type: PositionType::Absolute,
        left: px(12),
        top: top.map_or(Val::Auto, px),
        bottom: bottom.map_or(Val::Auto, px),
        padding: UiRect::axes(px(10), px(6)),
        ..default()
    };
    let row = |gap: f32| Node {
        align_items: AlignItems::Center,
        column_gap: px(gap),
        ..default()
    };
    // The stats, and under them the key: each level's colour, name and count.
    let key = |key: &mut ChildSpawnerCommands| {
        // The most detailed first, as the paper names them.
        for level in Lod::ALL.into_iter().rev() {
            key.spawn(row(6.0)).with_children(|entry| {
                entry.spawn((Swatch(level), Node::default(), BackgroundColor::DEFAULT));
                entry.spawn((HudText::Level(level), Text::default(), TextFont::from_font_size(size)));
            });
        }
    };
    commands
        .spawn(Node {
            flex_direction: FlexDirection::Column,
            align_items: AlignItems::FlexStart,
            row_gap: px(4),
            padding: UiRect::ZERO,
            ..at(Some(12.0), None)
        })
        .with_children(|hud| {
            let padded = |node: Node| Node {
                padding: UiRect::axes(px(10), px(6)),
                ..node
            };
            hud.spawn((
                HudText::Stats,
                Text::default(),
                TextFont::from_font_size(size),
                padded(default()),
                panel(),
            ));
            hud.spawn((padded(row(18.0)), panel().0)).with_children(key);
        });
    commands.spawn((
        HudText::Help,
        Text::default(),
        TextFont::from_font_size(size * 0.85),
        at(None, Some(12.0)),
        panel(),
    ));
    commands.spawn((
        HudText::Problems,
        Text::default(),
        TextFont::from_font_size(size),
        TextColor(Color::srgb(1.0, 0.85, 0.85)),
        BackgroundColor(Color::srgba(0.55, 0.0, 0.0, 0.85)),
        Node {
            position_type: PositionType::Absolute,
            left: px(12),
            right: px(12),
            bottom: px(60),
            padding: UiRect::all(px(10)),
            display: Display::None,
            ..default()
        },
    ));
    // The banner, centred.
    commands
        .spawn(Node {
            width: percent(100),
            height: percent(100),
            position_type: PositionType::Absolute,
            justify_content: JustifyContent::Center,
            align_items: AlignItems::Center,
            ..default()
        })
        .with_child((
            HudText::Banner,
            Text::default(),
            TextFont::from_font_size(settings.hud.banner_font_size_px),
            TextLayout::justify(Justify::Center),
            Node {
                padding: UiRect::all(px(24)),
                display: Display::None,
                ..default()
            },
            panel(),
        ));
}

fn stats_text(
    round: &Round,
    timing: &Timing,
    counts: &Summary,
    (config, budget): (&SimConfig, &BudgetTally),
    pops: Option<&PopTally>,
) -> String {
    let mut s = String::new();
    let score = round.score.unwrap_or(super::player::Score {
        survived_s: 0.0,
        collisions: 0,
    });
    let _ = writeln!(
        s,
        "ESCAPE THE PUCK   round {}\nsurvived {:.1} s   best {:.1} s   your collisions {}",
        round.number + 1,
        score.survived_s,
        round.best_survived_s,
        score.collisions
    );
    let hits: Vec<String> = counts
        .collisions
        .iter()
        .map(|(o, n)| format!("{} {n}", o.name()))
        .collect();
    let _ = writeln!(s, "collisions: {}   falls {}", hits.join(", "), counts.falls);
    // Only what the running policy reads: its radii, or its budget.
    let rules = &config.rules;
    let policy = config.scenario.level_policy;
    let _ = write!(s, "level policy: {}", policy.name());
    let mut radii = Vec::new();
    if policy.uses_puck_radius() {
        radii.push(format!("puck {:.0} m", rules.influence.puck_radius_m));
    }
    if policy.uses_camera_radius() {
        radii.push(format!("camera {:.0} m", rules.camera.radius_m));
    }
    if !radii.is_empty() {
        let _ = write!(s, "   radius of influence: {}", radii.join(", "));
    }
    if policy.uses_frame_budget() {
        let _ = write!(s, "   frame budget {:.1} ms", rules.budget.frame_budget_ms);
    }
    if pops.is_none() {
        return s;
    }
    // The developer's figures (P): the drawing's frame rate, and the simulation's own time.
    let _ = write!(
        s,
        "\ndrawing {:.1} frames/s   simulation {:.2} ms of wall time a frame (sharing the cores with the drawing)",
        timing.frames_per_s, timing.sim_ms_per_frame
    );
    if policy.uses_frame_budget() {
        let _ = write!(
            s,
            "\nbudget per 1/30 s: the cost model predicts {:.2} ms, the simulation took {:.2} ms{}{}",
            budget.predicted_us() / 1e3,
            timing.sim_ms_per_decision,
            if rules.budget.adaptive_frames > 0.0 {
                let keeps = match rules.budget.adaptive_percentile {
                    0.0 => String::new(),
                    p => format!(" ({p}th percentile within {}x)", rules.budget.adaptive_percentile_limit),
                };
                format!("   adaptive{keeps}: model x {:.2}", budget.correction)
            } else {
                String::new()
            },
            if budget.over_budget > 0 {
                format!("   over budget at {} decisions", budget.over_budget)
            } else {
                String::new()
            }
        );
    }
    if let Some(pops) = pops {
        let _ = write!(s, "\nlast switches, pop as drawn (P hides):");
        for ((from, to, forced), pop) in pops.recent.iter().rev() {
            let _ = write!(
                s,
                "\n  {} -> {}{}: {:.1} cm, {:.1} deg, {:.2} m/s",
                from.name(),
                to.name(),
                if *forced { " (forced)" } else { "" },
                pop.metres * 100.0,
                pop.degrees,
                pop.velocity_m_per_s
            );
        }
    }
    s
}

fn show_hud(
    real: Res<Time<Real>>,
    round: Res<Round>,
    timing: Res<Timing>,
    counts: Res<Counts>,
    (config, budget): (Res<SimConfig>, Res<BudgetTally>),
    problems: Res<Problems>,
    notice: Res<Notice>,
    show_figures: Res<ShowFigures>,
    pops: Res<PopTally>,
    mut texts: Query<(&HudText, &mut Text, &mut Node)>,
) {
    for (which, mut text, mut node) in &mut texts {
        let (shown, wanted) = match which {
            HudText::Stats => (
                true,
                stats_text(
                    &round,
                    &timing,
                    &counts.0,
                    (&config, &budget),
                    show_figures.0.then_some(&*pops),
                ),
            ),
            HudText::Level(level) => {
                let n = counts.0.levels[*level];
                (true, format!("{} {n}", level.name().replace('_', " ")))
            }
            HudText::Help => {
                let mut help = controls_help(config.scenario.level_policy);
                if real.elapsed_secs() < notice.until_s {
                    help = format!("{}\n{help}", notice.text);
                }
                (true, help)
            }
            HudText::Banner => {
                let score = round.score.map_or(0.0, |s| s.survived_s);
                let hits = round.score.map_or(0, |s| s.collisions);
                (
                    round.over,
                    format!(
                        "KNOCKED DOWN\nsurvived {score:.1} s with {hits} collision{}\n\
                         best this session {:.1} s\npress Enter to play again",
                        if hits == 1 { "" } else { "s" },
                        round.best_survived_s
                    ),
                )
            }
            HudText::Problems => {
                let lines: Vec<&str> = problems.0.values().map(String::as_str).collect();
                (
                    !lines.is_empty(),
                    format!("{}\n(the game runs on with the last good values)", lines.join("\n")),
                )
            }
        };
        let display = if shown { Display::Flex } else { Display::None };
        if node.display != display {
            node.display = display;
        }
        if text.0 != wanted {
            text.0 = wanted;
        }
    }
}

/// Font sizes follow `game.ron`.
fn resize_fonts(settings: Res<GameSettings>, mut texts: Query<(&HudText, &mut TextFont)>) {
    if !settings.is_changed() {
        return;
    }
    let h = &settings.hud;
    for (which, mut font) in &mut texts {
        let size = match which {
            HudText::Banner => h.banner_font_size_px,
            HudText::Help => h.font_size_px * 0.85,
            HudText::Stats | HudText::Level(_) | HudText::Problems => h.font_size_px,
        };
        font.font_size = size.into();
    }
}

/// The key's squares: the body colours from `game.ron`, hidden when colouring by level is off.
fn colour_key(
    settings: Res<GameSettings>,
    colour_by_level: Res<ColourByLevel>,
    mut swatches: Query<(&Swatch, &mut BackgroundColor, &mut Node)>,
) {
    if !settings.is_changed() && !colour_by_level.is_changed() {
        return;
    }
    let side = px(settings.hud.font_size_px * 0.8);
    for (swatch, mut colour, mut node) in &mut swatches {
        colour.0 = srgb(settings.level_colours_srgb[&swatch.0]);
        node.width = side;
        node.height = side;
        node.display = if colour_by_level.0 {
            Display::Flex
        } else {
            Display::None
        };
    }
}

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Timing>()
        .add_systems(Startup, spawn_hud)
        .add_systems(
            RunFixedMainLoop,
            (
                start_timing.in_set(RunFixedMainLoopSystems::BeforeFixedMainLoop),
                stop_timing.in_set(RunFixedMainLoopSystems::AfterFixedMainLoop),
            ),
        )
        .add_systems(Update, ((count, show_hud, resize_fonts).chain(), colour_key));
}
