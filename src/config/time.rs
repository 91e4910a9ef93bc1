//! How it works: `render.sun_time` as text. An instant is read as RFC 3339, its seconds optional
//! (`2026-06-21T17:30Z`, `2026-06-21T13:30:00-04:00`). The viewer's time-of-day knob reads the
//! hour of the UTC day that text names and sets it again keeping the date, today's (by the
//! system's clock) where the text names none; the instant it writes is whole seconds, in UTC.

use chrono::{DateTime, FixedOffset, NaiveDate, NaiveDateTime, Utc};

/// The last second of a day a time of day is set to.
const LAST_SECOND_OF_DAY: f64 = 86_399.0;

/// `text` as an instant (RFC 3339, seconds optional), or `None` where it names none.
pub fn parse_instant(text: &str) -> Option<DateTime<Utc>> {
    let text = text.trim();
    if let Ok(t) = DateTime::<FixedOffset>::parse_from_rfc3339(text) {
        return Some(t.with_timezone(&Utc));
    }
    // Minutes only: put the seconds in before the zone.
    let zone_at =
        text.rfind(['Z', 'z', '+']).or_else(|| text.get(11..).and_then(|t| t.rfind('-')).map(|i| i + 11))?;
    let (clock, zone) = text.split_at(zone_at);
    NaiveDateTime::parse_from_str(clock, "%Y-%m-%dT%H:%M").ok()?;
    DateTime::<FixedOffset>::parse_from_rfc3339(&format!("{clock}:00{zone}"))
        .ok()
        .map(|t| t.with_timezone(&Utc))
}

/// The hours since midnight UTC of the instant `text` names (0 to 24), or `None` where it names
/// none.
pub fn time_of_day_h(text: &str) -> Option<f64> {
    let t = parse_instant(text)?;
    let seconds = t.time().signed_duration_since(chrono::NaiveTime::MIN);
    Some(seconds.as_seconds_f64() / 3600.0)
}

/// The instant `hours` after midnight UTC (to the second, within the day) on the UTC date of the
/// instant `text` names, or of today where it names none, as RFC 3339.
pub fn at_time_of_day(text: &str, hours: f64) -> String {
    let date = parse_instant(text)
        .map_or_else(|| DateTime::<Utc>::from(std::time::SystemTime::now()).date_naive(), |t| t.date_naive());
    instant_on(date, hours)
}

fn instant_on(date: NaiveDate, hours: f64) -> String {
    let seconds = (hours * 3600.0).round().clamp(0.0, LAST_SECOND_OF_DAY) as u32;
    let (h, m, s) = (seconds / 3600, seconds / 60 % 60, seconds % 60);
    format!("{}T{h:02}:{m:02}:{s:02}Z", date.format("%Y-%m-%d"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn instants_read_with_or_without_seconds_in_any_zone() {
        let minutes = parse_instant("2026-06-21T17:30Z").unwrap();
        assert_eq!(minutes, parse_instant("2026-06-21T17:30:00Z").unwrap());
        assert_eq!(minutes, parse_instant("2026-06-21T13:30-04:00").unwrap());
        assert_eq!(minutes, parse_instant(" 2026-06-21T19:30+02:00 ").unwrap());
        for bad in ["", "noon", "2026-13-01T00:00Z", "2026-06-21 17:30", "2026-06-21T17:30"] {
            assert_eq!(parse_instant(bad), None, "{bad}");
        }
    }

    #[test]
    fn the_time_of_day_is_the_utc_hour_and_setting_it_keeps_the_utc_date() {
        // 23:30 at UTC−4 is 03:30 UTC the next day.
        let late = "2026-06-21T23:30-04:00";
        assert_eq!(time_of_day_h(late), Some(3.5));
        assert_eq!(at_time_of_day(late, 17.25), "2026-06-22T17:15:00Z");
        assert_eq!(time_of_day_h(&at_time_of_day(late, 17.25)), Some(17.25));
        // Whole seconds, within the day.
        assert_eq!(at_time_of_day(late, 0.0), "2026-06-22T00:00:00Z");
        assert_eq!(at_time_of_day(late, 24.0), "2026-06-22T23:59:59Z");
        assert_eq!(at_time_of_day(late, -1.0), "2026-06-22T00:00:00Z");
        assert_eq!(time_of_day_h(""), None);
    }

    #[test]
    fn without_a_date_the_time_of_day_falls_on_today() {
        let today = DateTime::<Utc>::from(std::time::SystemTime::now()).date_naive();
        let set = at_time_of_day("", 9.5);
        // The clock may pass midnight between the two reads.
        let dates = [today, today.succ_opt().unwrap()].map(|d| instant_on(d, 9.5));
        assert!(dates.contains(&set), "{set}");
    }
}
