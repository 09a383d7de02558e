package org.pdnav.app.ui

import android.content.Context
import android.os.Build
import android.util.TypedValue
import android.view.View
import android.widget.Button
import android.widget.LinearLayout
import android.widget.TextView

/** Small helpers for the programmatically built screens (no layout inflation, no AndroidX). */
internal object Views {
    fun button(ctx: Context, id: Int, text: CharSequence, onClick: () -> Unit) = Button(ctx).apply {
        this.id = id
        this.text = text
        // one line: the map screen's four buttons share 360 dp on small phones, where the
        // screen pictures (ScreensRoboTest) showed "NAVIGAT / E"; the text shrinks instead
        maxLines = 1
        if (Build.VERSION.SDK_INT >= 26) setAutoSizeTextTypeUniformWithConfiguration(9, 14, 1, TypedValue.COMPLEX_UNIT_SP)
        setOnClickListener { onClick() }
    }

    fun label(ctx: Context, text: CharSequence) = TextView(ctx).apply {
        this.text = text
        setPadding(0, 16, 0, 4)
    }

    fun row(ctx: Context, vararg views: View) = LinearLayout(ctx).apply {
        orientation = LinearLayout.HORIZONTAL
        views.forEach { addView(it, LinearLayout.LayoutParams(0, LinearLayout.LayoutParams.WRAP_CONTENT, 1f)) }
    }
}
